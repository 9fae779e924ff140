// The ROS 2 distro caracara-ros speaks (ros_discovery_info's Gid size, and sensor_msgs/Range's
// layout where no Range subscriber asks for one: RangeSubscribers): the config's range_layout when
// it names one, else what the peers' ros_discovery_info says (DistroDetector::choose, on the
// TelemetryPublisher's loop); read where a Gid is written or printed.
#pragma once

#include "tools/ros/ros_config.hpp"

#include <string>

namespace caracara::ros {

struct SpokenDistro {
    RangeLayout layout = RangeLayout::Humble;
    // Why, as the journal and /diagnostics say it ("range_layout in the config", "the peers'
    // ros_discovery_info: ...", "no ROS 2 peer seen yet: Humble's until one is").
    std::string why;
};

} // namespace caracara::ros

