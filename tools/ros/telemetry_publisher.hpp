// caracara-ros's reading connection to caracarad and the topics it publishes: the vehicle's
// objects (GetManagedObjects) kept current by PropertiesChanged; nothing is polled. imu, /tf,
// joint_states and thrusters/ordered go out at the config's sensor rate whether values change
// or not, each stamped with the time of the reading it carries; the others when caracarad
// announces a change, once per batch of signals. The topics (docs/ros2.md): imu, joint_states, thrusters/ordered,
// range/N, /diagnostics (at most 1 Hz, at once when a level changes), killed, state and
// kill_source (transient-local), /tf (unless the config leaves odom -> base_link to the
// vehicle's localization), /tf_static (the IMU's and each distance sensor's mount).
#pragma once

#include "tools/client/client.hpp"
#include "tools/client/object_mirror.hpp"
#include "tools/ros/command_record.hpp"
#include "tools/ros/dds_participant.hpp"
#include "tools/ros/distro_detector.hpp"
#include "tools/ros/range_subscribers.hpp"
#include "tools/ros/spoken_distro.hpp"
#include "tools/ros/static_frames.hpp"
#include "tools/ros/vehicle_diagnostics.hpp"

#include <array>
#include <memory>
#include <ctime>
#include <string>
#include <vector>

namespace caracara::ros {

class TelemetryPublisher {
public:
    // `commands`: the ROS writers' holder and refusals, a status of /diagnostics; its command
    // timeout is set from the daemon's CommandTimeoutMs. `distro`: what it speaks; unless the
    // config names it, chosen here from the peers' ros_discovery_info (and said why).
    TelemetryPublisher(sd_event* event, DdsParticipant& dds, const RosConfig& config, CommandRecord& commands,
                       SpokenDistro& distro);
    ~TelemetryPublisher();
    TelemetryPublisher(const TelemetryPublisher&) = delete;
    TelemetryPublisher& operator=(const TelemetryPublisher&) = delete;

    // Connects and loads the objects; retries every second while caracarad is not there.
    void start();
    // The reading connection (for Kill, which any client may send), or null while reconnecting.
    sd_bus* bus() const { return client_ ? client_->bus() : nullptr; }

private:
    enum Dirty : unsigned { kRanges = 4, kDiagnostics = 8, kState = 16 };
    static int on_flush(sd_event_source* s, void* userdata);
    static int on_retry(sd_event_source* s, uint64_t usec, void* userdata);
    static int on_diagnostics_due(sd_event_source* s, uint64_t usec, void* userdata);
    static int on_sensor_tick(sd_event_source* s, uint64_t usec, void* userdata);
    bool connect();
    void retry();
    void reload();
    void mark(unsigned dirty);
    void changed(const std::string& path, const client::Props& changes);
    void teensy_changed(const client::Props& changes);
    const client::Props& props(const std::string& path, const char* iface) const { return mirror_.props(path, iface); }

    void write_imu_and_tf();
    void write_joints();
    void write_ranges();
    void write_state();
    void choose_distro();

    sd_event* event_;
    DdsParticipant& dds_;
    const RosConfig& config_;
    CommandRecord& commands_;
    SpokenDistro& distro_;
    std::unique_ptr<DistroDetector> detector_; // none when the config names the distro
    RangeSubscribers range_subscribers_; // the Range layout written, and why
    // The Imu's and /tf's frame names in the config's convention (headers point into them).
    const std::string world_frame_, body_frame_;
    std::unique_ptr<client::Client> client_;
    const uint64_t sensor_period_us_;
    caracara::SourcePtr flush_, retry_, diagnostics_timer_, sensor_timer_;
    // When the readings the mirror holds were taken (CLOCK_REALTIME). The orientation: the time
    // caracarad gives with a changed value (OrientationReadNs), not its announcement's arrival,
    // which comes up to a telemetry period later, more on a loaded machine (a turning vehicle's
    // Imu would be that far behind its stamp). Otherwise the arrival of the object's latest
    // announcement of a reading: caracarad announces a changed value at its next telemetry tick,
    // so a later announcement of the Teensy's Frames or a thruster's counters (once a second)
    // says the value held was read again unchanged. Zero: nothing read yet.
    timespec orientation_read_at_{}, teensy_read_at_{}, thrusters_read_at_{};
    client::ObjectMirror mirror_;
    VehicleDiagnostics diagnostics_;
    StaticFrames static_frames_;
    unsigned dirty_ = 0;
    uint64_t diagnostics_last_us_ = 0;
    std::string last_state_, last_source_;
    bool state_written_ = false;

    dds_entity_t imu_, tf_ = 0, joints_, ordered_, killed_, state_, kill_source_;
    std::vector<dds_entity_t> ranges_;
    RangeLayout ranges_layout_{}; // the layout of ranges_' writers
    dds_topic_descriptor_t jazzy_range_;
};

} // namespace caracara::ros
