#include "tools/foxglove/dive_ros_mcap.hpp"

#include "core/frames.hpp"
#include "core/safety.hpp"
#include "tools/foxglove/cdr_writer.hpp"
#include "tools/foxglove/channels.hpp"
#include "tools/foxglove/mcap_writer.hpp"
#include "tools/ros/ros_conventions.hpp"

#include <algorithm>
#include <map>
#include <string>

namespace caracara::foxglove {

namespace dive = caracara::dive;
namespace ros = caracara::ros;

namespace {

// The ros2msg schemas: the message definition, then each type it uses after a line of "=" and
// "MSG: pkg/Type", as rosbag2 stores them.
const std::string kSep = "================================================================================\n";
const std::string kTime = kSep + "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
const std::string kHeader = kSep + "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n" + kTime;
const std::string kVector3 = kSep + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n";
const std::string kQuaternion = kSep + "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";

struct Topic {
    const char* name; // as ros_topic takes it: under the namespace unless it starts with "/"
    const char* type;
    std::string schema;
    bool latched = false; // transient-local, keep-last 1, as caracara-ros offers it
};

const Topic kImu{"imu", "sensor_msgs/msg/Imu",
                 "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
                 "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
                 "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n" +
                     kHeader + kQuaternion + kVector3};
const Topic kTf{"/tf", "tf2_msgs/msg/TFMessage",
                "geometry_msgs/TransformStamped[] transforms\n" + kSep +
                    "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n"
                    "geometry_msgs/Transform transform\n" + kHeader + kSep +
                    "MSG: geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n" +
                    kVector3 + kQuaternion};
const std::string kJointStateSchema =
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n" + kHeader;
const Topic kJoints{"joint_states", "sensor_msgs/msg/JointState", kJointStateSchema};
const Topic kOrdered{"thrusters/ordered", "sensor_msgs/msg/JointState", kJointStateSchema};
const std::string kRangeFields = "uint8 ULTRASOUND=0\nuint8 INFRARED=1\nstd_msgs/Header header\nuint8 radiation_type\n"
                                 "float32 field_of_view\nfloat32 min_range\nfloat32 max_range\nfloat32 range\n";
const std::string kRangeSchema = kRangeFields + kHeader;
const std::string kJazzyRangeSchema = kRangeFields + "float32 variance\n" + kHeader;
const Topic kDiagnostics{"/diagnostics", "diagnostic_msgs/msg/DiagnosticArray",
                         "std_msgs/Header header\ndiagnostic_msgs/DiagnosticStatus[] status\n" + kHeader + kSep +
                             "MSG: diagnostic_msgs/DiagnosticStatus\nbyte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\n"
                             "byte level\nstring name\nstring message\nstring hardware_id\ndiagnostic_msgs/KeyValue[] values\n" +
                             kSep + "MSG: diagnostic_msgs/KeyValue\nstring key\nstring value\n"};
const Topic kState{"state", "std_msgs/msg/String", "string data\n", true};
const Topic kKillSource{"kill_source", "std_msgs/msg/String", "string data\n", true};
const Topic kKilled{"killed", "std_msgs/msg/Bool", "bool data\n", true};
const Topic kTfStatic{"/tf_static", "tf2_msgs/msg/TFMessage", kTf.schema, true};

// The QoS caracara-ros offers on a topic (tools/ros/dds_qos.cpp), as rosbag2 keeps it in a
// channel's offered_qos_profiles: a YAML list of one profile, rosbag2_storage's field names and
// rmw's policy numbers (history 1 keep-last; reliability 1 reliable; durability 1 transient-local,
// 2 volatile; liveliness 1 automatic; durations 0 unspecified). Numbers, not Jazzy's words: a
// bag without serialized_metadata is read as version 8, which takes numbers, as Humble does.
std::string offered_qos(bool latched) {
    const std::string zero = "\n    sec: 0\n    nsec: 0\n";
    return std::string("- history: 1\n  depth: ") + (latched ? "1" : "10") + "\n  reliability: 1\n  durability: " +
           (latched ? "1" : "2") + "\n  deadline:" + zero + "  lifespan:" + zero + "  liveliness: 1\n" +
           "  liveliness_lease_duration:" + zero + "  avoid_ros_namespace_conventions: false\n";
}

constexpr uint64_t kDiagnosticsPeriodNs = 1'000'000'000;
const char* const kBusStates[] = {"ok", "recovering", "lost", "lost"};

class RosBag {
public:
    RosBag(const ros::RosConfig& config, ros::RangeLayout distro) : config_(config), w_("ros2", "caracaractl export") {
        // rosbag2's record of the bag: `ros2 bag info` shows the distro.
        w_.add_metadata("rosbag2", {{"ROS_DISTRO", std::string(name_of(distro))}});
    }

    void put(const Topic& t, uint64_t ns, const CdrWriter& m) { put(t.name, t, ns, m); }
    void put(const std::string& topic, const Topic& t, uint64_t ns, const CdrWriter& m) {
        const std::string name = ros::ros_topic(config_, topic);
        auto it = channels_.find(name);
        if (it == channels_.end()) {
            auto s = schemas_.find(t.type);
            if (s == schemas_.end())
                s = schemas_.emplace(t.type, w_.add_schema(t.type, "ros2msg", t.schema)).first;
            it = channels_.emplace(name, w_.add_channel(s->second, name, "cdr",
                                                        {{"offered_qos_profiles", offered_qos(t.latched)}})).first;
        }
        const auto& b = m.bytes();
        w_.add_message(it->second, ns, ns, std::string_view(reinterpret_cast<const char*>(b.data()), b.size()));
    }
    std::vector<uint8_t> finish() { return w_.finish(); }

private:
    const ros::RosConfig& config_;
    McapWriter w_;
    std::map<std::string, uint16_t> schemas_, channels_;
};

void joint_state(CdrWriter& m, uint64_t ns, const std::string& base_frame, const std::vector<double>& velocity,
                 const std::vector<double>& effort) {
    m.header(ns, base_frame);
    m.u32(ros::kThrusterJoints);
    for (unsigned i = 0; i < ros::kThrusterJoints; ++i)
        m.string(ros::thruster_joint_name(i));
    m.u32(0); // no positions: a thruster spins
    m.u32(static_cast<uint32_t>(velocity.size()));
    for (const double v : velocity)
        m.f64(v);
    m.u32(static_cast<uint32_t>(effort.size()));
    for (const double e : effort)
        m.f64(e);
}

void state_messages(RosBag& bag, uint64_t ns, const std::string& state, const std::string& source) {
    CdrWriter s, k, b;
    s.string(state);
    k.string(source);
    b.boolean(ros::state_is_killed(state));
    bag.put(kState, ns, s);
    bag.put(kKillSource, ns, k);
    bag.put(kKilled, ns, b);
}

void diagnostics(RosBag& bag, uint64_t ns, const dive::Sample& s, const std::string& state) {
    CdrWriter m;
    m.header(ns, "");
    m.u32(ros::kThrusterJoints + 3);
    auto status = [&](uint8_t level, const std::string& name, const std::string& message) {
        m.u8(level);
        m.string(name);
        m.string(message);
        m.string(""); // hardware_id: the dive does not record it
        m.u32(0);
    };
    for (unsigned i = 0; i < ros::kThrusterJoints; ++i) {
        const dive::ThrusterSample& t = s.thrusters[i];
        const bool online = t.flags & dive::kOnline;
        const std::vector<std::string> faults = fault_names(t.faults);
        std::string list;
        for (const auto& f : faults)
            list += (list.empty() ? "" : ",") + f;
        status(!online ? 2 : faults.empty() ? 0 : 1, "caracara: " + ros::thruster_joint_name(i),
               !online ? "unreachable" : faults.empty() ? "ok" : "faults: " + list);
    }
    const char* bus = kBusStates[s.bus_state()];
    status(s.bus_state() == 0 ? 0 : s.bus_state() == 1 ? 1 : 2, "caracara: i2c bus", bus);
    const bool teensy = s.flags & dive::kTeensyOnline;
    status(teensy ? 0 : 2, "caracara: teensy", teensy ? "online" : "offline");
    status(state == "fault" ? 2 : state == "ready" || state == "arming" ? 0 : 1, "caracara: vehicle", state);
    bag.put(kDiagnostics, ns, m);
}

} // namespace

// /tf_static as caracara-ros sends it at its start: every mount under the base frame itself.
void static_frames(RosBag& bag, uint64_t ns, const ros::RosConfig& config, std::size_t ranges) {
    const std::vector<ros::SensorMount> mounts = ros::sensor_mounts(config, ranges);
    CdrWriter m;
    m.u32(static_cast<uint32_t>(mounts.size()));
    for (const ros::SensorMount& s : mounts) {
        const frames::Quaternion q = ros::mount_rotation(s);
        m.header(ns, config.base_frame);
        m.string(s.frame);
        for (const double v : {s.xyz.x, s.xyz.y, s.xyz.z, q.x, q.y, q.z, q.w})
            m.f64(v);
    }
    bag.put(kTfStatic, ns, m);
}

std::vector<uint8_t> dive_to_ros_mcap(const dive::Dive& d, const ros::RosConfig& config, ros::RangeLayout distro) {
    RosBag bag(config, distro);
    // The Imu's and /tf's frames in the config's convention, as caracara-ros names them.
    const std::string world = ros::world_frame_id(config.world_frame, config.frame_convention),
                      body = ros::body_frame_id(config.base_frame, config.frame_convention);
    const bool jazzy = distro == ros::RangeLayout::Jazzy;
    const uint64_t start_ns = d.header.start_unix_ms * 1'000'000u;
    auto at = [&](uint32_t t_100us) { return start_ns + uint64_t{t_100us} * 100'000u; };
    // A dive starts at a ClearKill or the daemon's start: arming, as dive_mcap.cpp has it.
    std::string state = "arming", source, written;
    // Changes only, like the live latched topics.
    auto state_changed = [&](uint64_t ns) {
        if (written == state + "\n" + source)
            return;
        written = state + "\n" + source;
        state_messages(bag, ns, state, source);
    };
    state_changed(start_ns);
    std::size_t ranges = 0;
    for (const dive::Sample& s : d.samples)
        ranges = std::max(ranges, s.distances.size());
    static_frames(bag, start_ns, config, ranges);
    std::size_t next_event = 0;
    auto events_until = [&](uint32_t t) {
        for (; next_event < d.events.size() && d.events[next_event].t_100us <= t; ++next_event) {
            const dive::Event& e = d.events[next_event];
            if (e.kind != dive::EventKind::State)
                continue;
            const auto s = static_cast<SafetyState>(e.state);
            state = std::string(state_name(s));
            source = s == SafetyState::Killed ? std::string(kill_source_name(static_cast<KillSource>(e.kill_source))) : "";
            state_changed(at(e.t_100us));
        }
    };
    uint64_t diagnostics_ns = 0;
    bool diagnostics_written = false;
    for (const dive::Sample& s : d.samples) {
        events_until(s.t_100us);
        const uint64_t ns = at(s.t_100us);
        // REP 103 / 145 (or NED / FRD) as caracara-ros: the body frame in the world frame.
        const frames::Quaternion q =
            frames::orientation({s.orientation[0], s.orientation[1], s.orientation[2]}, config.frame_convention);
        CdrWriter imu;
        imu.header(ns, body);
        for (const double v : {q.x, q.y, q.z, q.w})
            imu.f64(v);
        // REP 145, as caracara-ros: orientation covariance unknown (zeros); no angular velocity
        // or linear acceleration (-1 first).
        auto covariance = [&](double first) {
            imu.f64(first);
            for (int k = 1; k < 9; ++k)
                imu.f64(0);
        };
        auto zero_vector = [&] {
            for (int k = 0; k < 3; ++k)
                imu.f64(0);
        };
        covariance(0);   // orientation_covariance
        zero_vector();   // angular_velocity
        covariance(-1);  // angular_velocity_covariance
        zero_vector();   // linear_acceleration
        covariance(-1);  // linear_acceleration_covariance
        bag.put(kImu, ns, imu);
        if (config.publish_odom_tf) { // else the vehicle's localization publishes it
            CdrWriter tf;
            tf.u32(1);
            tf.header(ns, world);
            tf.string(body);
            for (const double v : {0.0, 0.0, 0.0, q.x, q.y, q.z, q.w})
                tf.f64(v);
            bag.put(kTf, ns, tf);
        }
        std::vector<double> speed, current, ordered;
        for (unsigned i = 0; i < ros::kThrusterJoints; ++i) {
            const dive::ThrusterSample& t = s.thrusters[i];
            speed.push_back(t.speed == dive::kUnknownSpeed ? 0.0 : ros::motor_fraction(t.speed));
            current.push_back((t.flags & dive::kCurrentKnown) ? t.current_da / 10.0 : 0.0);
            ordered.push_back(ros::motor_fraction(s.applied[i]));
        }
        CdrWriter joints, orders;
        joint_state(joints, ns, config.base_frame, speed, current);
        joint_state(orders, ns, config.base_frame, ordered, {});
        bag.put(kJoints, ns, joints);
        bag.put(kOrdered, ns, orders);
        for (std::size_t i = 0; i < s.distances.size(); ++i) {
            CdrWriter r;
            r.header(ns, ros::range_mount(config, i).frame);
            r.u8(0); // ULTRASOUND: the Teensy does not say which kind of sensor it reads
            for (const float v : {config.range_fov_rad, config.range_min_m, config.range_max_m, ros::range_metres(s.distances[i])})
                r.f32(v);
            if (jazzy)
                r.f32(0.0f); // variance: unknown
            bag.put("range/" + std::to_string(i),
                    Topic{"", "sensor_msgs/msg/Range", jazzy ? kJazzyRangeSchema : kRangeSchema}, ns, r);
        }
        if (!diagnostics_written || ns >= diagnostics_ns + kDiagnosticsPeriodNs) {
            diagnostics(bag, ns, s, state);
            diagnostics_ns = ns;
            diagnostics_written = true;
        }
    }
    events_until(UINT32_MAX);
    return bag.finish();
}

} // namespace caracara::foxglove
