// /tf_static as tf2's static broadcaster keeps it: reliable, transient-local, keep-last 1, one
// TFMessage holding every static transform (a late subscriber gets them all at once): the IMU's
// and each distance sensor's mount under the base frame (REP 103's body FLU).
#pragma once

#include "tools/ros/dds_participant.hpp"

#include <cstddef>

namespace caracara::ros {

class StaticFrames {
public:
    StaticFrames(DdsParticipant& dds, const RosConfig& config);

    // Every mount: the config's and, up to `ranges`, those the Teensy reports (at the origin).
    void write(std::size_t ranges);
    bool written() const { return written_; }

private:
    const RosConfig& config_;
    dds_entity_t writer_;
    bool written_ = false;
};

} // namespace caracara::ros
