// /diagnostics (diagnostic_msgs/DiagnosticArray, as a ROS 2 driver's diagnostic_updater sends
// it): one status per thruster, the bus, the Teensy, the failsafes, the vehicle, the ROS commands
// (holder, refusals), the distro spoken and the Range layout, read from the mirrored objects;
// each level change is logged too. When to write is the TelemetryPublisher's (about 1 Hz, at
// once when a level changes).
#pragma once

#include "tools/client/object_mirror.hpp"
#include "tools/ros/command_record.hpp"
#include "tools/ros/dds_participant.hpp"
#include "tools/ros/distro_detector.hpp"
#include "tools/ros/range_subscribers.hpp"
#include "tools/ros/spoken_distro.hpp"

#include <cstdint>
#include <vector>

namespace caracara::ros {

class VehicleDiagnostics {
public:
    // `detector`: null when the config names the distro.
    VehicleDiagnostics(DdsParticipant& dds, const client::ObjectMirror& mirror, const RosConfig& config,
                       const CommandRecord& commands, const SpokenDistro& distro, const DistroDetector* detector,
                       const RangeSubscribers& range_subscribers);

    // Whether a status's level differs from the last written.
    bool level_changed() const { return levels() != last_levels_; }
    void write();

private:
    // OK 0, WARN 1, ERROR 2 for: each thruster, the bus, the Teensy, the failsafes, the vehicle,
    // the ROS commands, the distro, the Range layout.
    std::vector<uint8_t> levels() const;
    const client::Props& props(const std::string& path, const char* iface) const { return mirror_.props(path, iface); }

    const client::ObjectMirror& mirror_;
    const RosConfig& config_;
    const CommandRecord& commands_;
    const SpokenDistro& distro_;
    const DistroDetector* detector_;
    const RangeSubscribers& range_subscribers_;
    dds_entity_t writer_;
    std::vector<uint8_t> last_levels_;
};

} // namespace caracara::ros
