#include "tools/ros/telemetry_publisher.hpp"

#include "core/clock.hpp"
#include "core/frames.hpp"
#include "drivers/protocol/seabotix.hpp"
#include "tools/ros/ros_conventions.hpp"
#include "tools/ros/type_name.hpp"

#include <cmath>
#include <cstdio>
#include <ros_msgs.h>
#include <ctime>
#include <utility>

namespace caracara::ros {

using client::Props;
using client::Value;

namespace {

const std::string kRoot = caracara::dbus::kRootPath;
const std::string kThrusterPrefix = kRoot + "/thruster/";
constexpr unsigned kThrusters = kThrusterJoints;
constexpr uint64_t kDiagnosticsPeriodUs = 1'000'000; // a diagnostics monitor's expectation: about 1 Hz
constexpr uint64_t kRefusalWarnNs = 10'000'000'000;   // how long a refused command keeps "ros commands" at WARN

const Value kNone;
const Value& get(const Props& p, const char* name) {
    const auto it = p.find(name);
    return it == p.end() ? kNone : it->second;
}
char* c_str(const std::string& s) { return const_cast<char*>(s.c_str()); }

timespec realtime_now() {
    timespec t{};
    clock_gettime(CLOCK_REALTIME, &t);
    return t;
}

// The header's frame_id points into `frame`, which must outlive the message's write. `at`: the
// time of the reading the message carries (now for what has no reading: diagnostics, state).
std_msgs_msg_dds__Header_ header(const std::string& frame, const timespec& at = realtime_now()) {
    return {{static_cast<int32_t>(at.tv_sec), static_cast<uint32_t>(at.tv_nsec)}, c_str(frame)};
}

int thruster_of(const std::string& path) {
    if (!path.starts_with(kThrusterPrefix) || path.size() != kThrusterPrefix.size() + 1)
        return -1;
    const int n = path.back() - '0';
    return n >= 0 && n < static_cast<int>(kThrusters) ? n : -1;
}

// The thruster's reported SPEED byte as a fraction of full thrust (-1..1), 0 when unknown.
double actual_fraction(const Props& p) {
    const auto m = caracara::speed_to_motor(static_cast<uint8_t>(get(p, "ActualSpeed").unsigned_integer()));
    return m ? motor_fraction(*m) : 0.0;
}

} // namespace

TelemetryPublisher::TelemetryPublisher(sd_event* event, DdsParticipant& dds, const RosConfig& config,
                                       CommandRecord& commands, SpokenDistro& distro)
    : event_(event), dds_(dds), config_(config), commands_(commands), distro_(distro),
      detector_(config.range_layout_given ? nullptr : std::make_unique<DistroDetector>(dds.handle())),
      range_subscribers_(dds.handle(), config, distro),
      world_frame_(world_frame_id(config.world_frame, config.frame_convention)),
      body_frame_(body_frame_id(config.base_frame, config.frame_convention)),
      sensor_period_us_(static_cast<uint64_t>(1e6 / config.sensor_rate_hz)),
      mirror_([this](const std::string& path, const std::string&, const Props& changes,
                     const Props&) { changed(path, changes); },
              [this] { reload(); }),
      jazzy_range_(under_type_name(jazzy_sensor_msgs_msg_dds__Range__desc, "sensor_msgs::msg::dds_::Range_")) {
    commands_.on_change([this] { mark(kDiagnostics); }); // a refusal on /diagnostics within a second
    const auto topic = [&](const char* name) { return ros_topic(config_, name); };
    imu_ = dds_.writer(&sensor_msgs_msg_dds__Imu__desc, topic("imu"), Profile::Default);
    if (config_.publish_odom_tf) // else no writer at all: ros2 topic info /tf names only the localization's
        tf_ = dds_.writer(&tf2_msgs_msg_dds__TFMessage__desc, "/tf", Profile::Default);
    // As tf2's static broadcaster: reliable, transient-local, keep-last 1, one TFMessage holding
    // every static transform (a late subscriber gets them all at once).
    tf_static_ = dds_.writer(&tf2_msgs_msg_dds__TFMessage__desc, "/tf_static", Profile::Latched);
    joints_ = dds_.writer(&sensor_msgs_msg_dds__JointState__desc, topic("joint_states"), Profile::Default);
    ordered_ = dds_.writer(&sensor_msgs_msg_dds__JointState__desc, topic("thrusters/ordered"), Profile::Default);
    diagnostics_ = dds_.writer(&diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics", Profile::Default);
    killed_ = dds_.writer(&std_msgs_msg_dds__Bool__desc, topic("killed"), Profile::Latched);
    state_ = dds_.writer(&std_msgs_msg_dds__String__desc, topic("state"), Profile::Latched);
    kill_source_ = dds_.writer(&std_msgs_msg_dds__String__desc, topic("kill_source"), Profile::Latched);
    sd_event_source* s = nullptr;
    if (sd_event_add_defer(event_, &s, on_flush, this) >= 0) {
        flush_.reset(s);
        sd_event_source_set_enabled(s, SD_EVENT_OFF);
    }
    // The sensor topics' steady rate: a timer of its own, accurate to 1 ms (sd-event's default
    // accuracy, 250 ms, would bunch the messages).
    uint64_t now = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now);
    s = nullptr;
    if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now + sensor_period_us_, 1000, on_sensor_tick, this) >= 0) {
        sensor_timer_.reset(s);
        sd_event_source_set_enabled(s, SD_EVENT_ON);
    }
}

TelemetryPublisher::~TelemetryPublisher() { mirror_.clear(); }

void TelemetryPublisher::start() {
    if (!sent_static_frames_) // the config's sensors at once; the Teensy's others when it reports them
        write_static_frames();
    if (!connect())
        retry();
}

void TelemetryPublisher::retry() {
    sd_event_source* s = nullptr;
    uint64_t now = 0;
    sd_event_now(event_, CLOCK_MONOTONIC, &now);
    if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now + 1'000'000, 0, on_retry, this) >= 0)
        retry_.reset(s);
}

int TelemetryPublisher::on_retry(sd_event_source*, uint64_t, void* userdata) {
    static_cast<TelemetryPublisher*>(userdata)->start();
    return 0;
}

bool TelemetryPublisher::connect() {
    mirror_.clear();
    client_ = std::make_unique<client::Client>(config_.bus);
    try {
        if (!mirror_.subscribe_and_load(*client_))
            return false;
        if (sd_bus_attach_event(client_->bus(), event_, SD_EVENT_PRIORITY_NORMAL) < 0)
            return false;
    } catch (const client::Failure& f) {
        std::fprintf(stderr, "caracara-ros: caracarad not reachable (%s); retrying\n", f.message.c_str());
        mirror_.clear();
        client_.reset();
        return false;
    }
    orientation_read_at_ = teensy_read_at_ = thrusters_read_at_ = realtime_now();
    commands_.set_timeout_ms(get(props(kRoot, caracara::dbus::kVehicleIface), "CommandTimeoutMs").unsigned_integer());
    mark(kRanges | kDiagnostics | kState);
    return true;
}

void TelemetryPublisher::reload() {
    // A restarted caracarad: its objects are loaded again (the old values are gone). The call
    // waits for its reply on this connection, which sd-bus allows from a handler.
    try {
        mirror_.load(*client_);
    } catch (const client::Failure& f) {
        std::fprintf(stderr, "caracara-ros: reloading caracarad's objects failed (%s)\n", f.message.c_str());
        return;
    }
    orientation_read_at_ = teensy_read_at_ = thrusters_read_at_ = realtime_now();
    commands_.set_timeout_ms(get(props(kRoot, caracara::dbus::kVehicleIface), "CommandTimeoutMs").unsigned_integer());
    mark(kRanges | kDiagnostics | kState);
}

void TelemetryPublisher::changed(const std::string& path, const Props& changes) {
    unsigned d = kDiagnostics;
    if (path == kRoot) {
        if (changes.contains("State") || changes.contains("KillSource"))
            d |= kState;
    } else if (thruster_of(path) >= 0) {
        thrusters_read_at_ = realtime_now();
    } else if (path == caracara::dbus::kTeensyPath) {
        teensy_changed(changes);
        // A reading per Teensy poll (each announces its Frames count), changed or not: a range
        // sensor's subscribers expect a steady stream, not only the changes.
        if (changes.contains("Distances") || changes.contains("Frames"))
            d |= kRanges;
    }
    mark(d);
}

void TelemetryPublisher::teensy_changed(const Props& changes) {
    // Its link counters and state (BusyRetries, LinkErrors, Online, Task...) are no reading: a
    // stalled poll's retries say nothing of when the orientation was read.
    const bool reading = changes.contains("Orientation") || changes.contains("Distances") || changes.contains("Frames");
    if (!reading)
        return;
    const timespec now = realtime_now();
    teensy_read_at_ = now;
    timespec at = now; // an unchanged value confirmed: as of this announcement
    // Announced with the Orientation it dates (0 from a caracarad that does not give it).
    const uint64_t read_ns = get(changes, "OrientationReadNs").unsigned_integer();
    const uint64_t mono = monotonic_ns();
    if (changes.contains("Orientation") && read_ns && read_ns <= mono) {
        // The reading's CLOCK_MONOTONIC time (caracarad's, on this machine) as CLOCK_REALTIME.
        const uint64_t ns = static_cast<uint64_t>(now.tv_sec) * 1'000'000'000ull + static_cast<uint64_t>(now.tv_nsec) -
                            (mono - read_ns);
        at = {static_cast<time_t>(ns / 1'000'000'000ull), static_cast<long>(ns % 1'000'000'000ull)};
    }
    // Never back in time (tf2 drops a transform older than the last): a confirmation's arrival
    // may be later than the next change's reading.
    if (at.tv_sec > orientation_read_at_.tv_sec ||
        (at.tv_sec == orientation_read_at_.tv_sec && at.tv_nsec > orientation_read_at_.tv_nsec))
        orientation_read_at_ = at;
}

void TelemetryPublisher::mark(unsigned dirty) {
    // One message per topic for all the changes one batch of signals brings.
    dirty_ |= dirty;
    if (flush_)
        sd_event_source_set_enabled(flush_.get(), SD_EVENT_ONESHOT);
}

int TelemetryPublisher::on_flush(sd_event_source*, void* userdata) {
    auto* self = static_cast<TelemetryPublisher*>(userdata);
    const unsigned d = self->dirty_;
    self->dirty_ = 0;
    if (d & kState)
        self->write_state();
    if (d & kRanges)
        self->write_ranges();
    if (d & kDiagnostics) {
        uint64_t now = 0;
        sd_event_now(self->event_, CLOCK_MONOTONIC, &now);
        const bool level_changed = self->levels() != self->last_levels_;
        if (level_changed || now >= self->diagnostics_last_us_ + kDiagnosticsPeriodUs) {
            self->diagnostics_timer_.reset();
            self->write_diagnostics();
            self->diagnostics_last_us_ = now;
        } else if (!self->diagnostics_timer_) {
            sd_event_source* s = nullptr;
            if (sd_event_add_time(self->event_, &s, CLOCK_MONOTONIC, self->diagnostics_last_us_ + kDiagnosticsPeriodUs,
                                  0, on_diagnostics_due, self) >= 0)
                self->diagnostics_timer_.reset(s);
        }
    }
    return 0;
}

int TelemetryPublisher::on_diagnostics_due(sd_event_source*, uint64_t usec, void* userdata) {
    auto* self = static_cast<TelemetryPublisher*>(userdata);
    self->diagnostics_timer_.reset();
    self->write_diagnostics();
    self->diagnostics_last_us_ = usec;
    return 0;
}

int TelemetryPublisher::on_sensor_tick(sd_event_source* s, uint64_t usec, void* userdata) {
    auto* self = static_cast<TelemetryPublisher*>(userdata);
    // From the due time, not from now: a late tick does not slow the rate down. After a stall of
    // more than a period the missed ticks are skipped, not sent in a burst of the same reading.
    uint64_t now = 0;
    sd_event_now(self->event_, CLOCK_MONOTONIC, &now);
    const uint64_t next = usec + self->sensor_period_us_;
    sd_event_source_set_time(s, next > now ? next : now + self->sensor_period_us_);
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    if (self->detector_ && self->detector_->update())
        self->choose_distro();
    if (self->range_subscribers_.update()) // a Range subscriber came or left, or the layout changed
        self->mark(kDiagnostics | kRanges);
    if (!self->client_ || !self->orientation_read_at_.tv_sec)
        return 0; // nothing read yet
    // An offline Teensy's last attitude is no reading: the Imu and /tf stop, as a driver's do
    // when its sensor goes quiet (the diagnostics say why).
    if (get(self->props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Online").boolean())
        self->write_imu_and_tf();
    self->write_joints();
    return 0;
}

void TelemetryPublisher::write_state() {
    const Props& p = props(kRoot, caracara::dbus::kVehicleIface);
    const std::string state = get(p, "State").s, source = get(p, "KillSource").s;
    if (state_written_ && state == last_state_ && source == last_source_)
        return; // latched topics carry changes only
    std_msgs_msg_dds__Bool_ killed{state_is_killed(state)};
    dds_write(killed_, &killed);
    std_msgs_msg_dds__String_ s{c_str(state)};
    dds_write(state_, &s);
    std_msgs_msg_dds__String_ k{c_str(source)};
    dds_write(kill_source_, &k);
    last_state_ = state;
    last_source_ = source;
    state_written_ = true;
}

void TelemetryPublisher::write_imu_and_tf() {
    const Value& o = get(props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Orientation");
    if (o.items.size() != 3)
        return;
    // REP 145: the orientation of the body frame in the world frame, in the config's convention.
    const frames::Quaternion r = frames::orientation({o.items[0].number(), o.items[1].number(), o.items[2].number()},
                                                     config_.frame_convention);
    const geometry_msgs_msg_dds__Quaternion_ q{r.x, r.y, r.z, r.w};
    sensor_msgs_msg_dds__Imu_ imu{};
    imu.header = header(body_frame_, orientation_read_at_);
    imu.orientation = q;
    // REP 145: the orientation's covariance is unknown (all zeros); the Teensy gives no angular
    // velocity or linear acceleration, marked by -1 in the first element of their covariances.
    imu.angular_velocity_covariance[0] = -1;
    imu.linear_acceleration_covariance[0] = -1;
    dds_write(imu_, &imu);
    if (!config_.publish_odom_tf)
        return;
    geometry_msgs_msg_dds__TransformStamped_ t{};
    t.header = header(world_frame_, orientation_read_at_);
    t.child_frame_id = c_str(body_frame_);
    t.transform.rotation = q;
    tf2_msgs_msg_dds__TFMessage_ tf{};
    tf.transforms = {1, 1, &t, false};
    dds_write(tf_, &tf);
}

void TelemetryPublisher::write_joints() {
    std::vector<std::string> names;
    std::vector<char*> name_ptrs;
    std::vector<double> actual, current, ordered;
    for (unsigned i = 0; i < kThrusters; ++i) {
        const Props& p = props(kThrusterPrefix + std::to_string(i), caracara::dbus::kThrusterIface);
        names.push_back(thruster_joint_name(i));
        actual.push_back(actual_fraction(p));
        current.push_back(get(p, "Current").number());
        ordered.push_back(motor_fraction(static_cast<int32_t>(get(p, "OrderedValue").integer())));
    }
    for (auto& n : names)
        name_ptrs.push_back(c_str(n));
    std::vector<double> none;
    const auto n = static_cast<uint32_t>(names.size());
    // velocity: the reported speed as a fraction of full thrust; effort: the current in A.
    sensor_msgs_msg_dds__JointState_ js{header(config_.base_frame, thrusters_read_at_), {n, n, name_ptrs.data(), false}, {0, 0, nullptr, false},
                                        {n, n, actual.data(), false}, {n, n, current.data(), false}};
    dds_write(joints_, &js);
    sensor_msgs_msg_dds__JointState_ os{header(config_.base_frame, thrusters_read_at_), {n, n, name_ptrs.data(), false}, {0, 0, nullptr, false},
                                        {n, n, ordered.data(), false}, {0, 0, nullptr, false}};
    dds_write(ordered_, &os);
}

void TelemetryPublisher::write_ranges() {
    if (ranges_layout_ != range_subscribers_.layout()) { // Range's layout changed: its writers made anew
        for (const dds_entity_t w : std::exchange(ranges_, {}))
            dds_.delete_writer(w);
        ranges_layout_ = range_subscribers_.layout();
    }
    const Value& d = get(props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Distances");
    const bool more = d.items.size() > ranges_.size();
    for (std::size_t i = ranges_.size(); i < d.items.size(); ++i)
        ranges_.push_back(dds_.writer(range_subscribers_.layout() == RangeLayout::Jazzy ? &jazzy_range_ : &sensor_msgs_msg_dds__Range__desc,
                                      ros_topic(config_, "range/" + std::to_string(i)), Profile::Default));
    if (more && d.items.size() > config_.ranges.size())
        write_static_frames(); // a sensor the config does not list: its frame, at the origin
    for (std::size_t i = 0; i < d.items.size(); ++i) {
        const std::string frame = range_mount(config_, i).frame;
        const float metres = range_metres(static_cast<uint32_t>(d.items[i].unsigned_integer()));
        // radiation_type ULTRASOUND (0): the Teensy does not say which kind of sensor it reads.
        if (range_subscribers_.layout() == RangeLayout::Jazzy) {
            jazzy_sensor_msgs_msg_dds__Range_ r{header(frame, teensy_read_at_), 0, config_.range_fov_rad, config_.range_min_m,
                                                config_.range_max_m, metres, 0.0f};
            dds_write(ranges_[i], &r);
        } else {
            sensor_msgs_msg_dds__Range_ r{header(frame, teensy_read_at_), 0, config_.range_fov_rad, config_.range_min_m,
                                          config_.range_max_m, metres};
            dds_write(ranges_[i], &r);
        }
    }
}

void TelemetryPublisher::choose_distro() {
    const unsigned humble = detector_->peers(RangeLayout::Humble), jazzy = detector_->peers(RangeLayout::Jazzy);
    if (!humble && !jazzy)
        return; // the last peer left: what it spoke stays until another says otherwise
    const RangeLayout before = distro_.layout;
    const auto count = [](unsigned n) { return std::to_string(n) + (n == 1 ? " participant" : " participants"); };
    if (!humble || !jazzy) {
        distro_.layout = humble ? RangeLayout::Humble : RangeLayout::Jazzy;
        distro_.why = "the peers' ros_discovery_info: " + count(humble + jazzy) + ", all " +
                      std::string(name_of(distro_.layout));
    } else {
        // Both: the distro of more peers (on a tie, the one spoken already: no flapping). The
        // others cannot read Range nor list this node: a setting to make (range_layout).
        if (humble != jazzy)
            distro_.layout = humble > jazzy ? RangeLayout::Humble : RangeLayout::Jazzy;
        distro_.why = "peers of both distros (humble " + count(humble) + ", jazzy " + count(jazzy) + "): " +
                      std::string(name_of(distro_.layout)) + (humble != jazzy ? ", the more" : ", spoken already") +
                      "; the others cannot read Range or list this node (set range_layout to choose)";
    }
    std::fprintf(stderr, "caracara-ros: speaking %s: %s\n", std::string(name_of(distro_.layout)).c_str(),
                 distro_.why.c_str());
    mark(kDiagnostics);
    if (distro_.layout != before) // ros_discovery_info's Gid; Range's layout follows in range_subscribers_
        dds_.discovery_info().set_layout(distro_.layout);
}

void TelemetryPublisher::write_static_frames() {
    const std::vector<SensorMount> mounts = sensor_mounts(config_, ranges_.size());
    std::vector<geometry_msgs_msg_dds__TransformStamped_> ts;
    const timespec now = realtime_now();
    for (const SensorMount& m : mounts) {
        const frames::Quaternion q = mount_rotation(m);
        ts.push_back({header(config_.base_frame, now), c_str(m.frame), {{m.xyz.x, m.xyz.y, m.xyz.z}, {q.x, q.y, q.z, q.w}}});
    }
    // The headers and child frames point into `mounts`, alive until the write returns.
    tf2_msgs_msg_dds__TFMessage_ tf{};
    tf.transforms = {static_cast<uint32_t>(ts.size()), static_cast<uint32_t>(ts.size()), ts.data(), false};
    dds_write(tf_static_, &tf);
    sent_static_frames_ = true;
}

// OK 0, WARN 1, ERROR 2 for: each thruster, the bus, the Teensy, the failsafes, the vehicle.
std::vector<uint8_t> TelemetryPublisher::levels() const {
    std::vector<uint8_t> out;
    for (unsigned i = 0; i < kThrusters; ++i) {
        const Props& p = props(kThrusterPrefix + std::to_string(i), caracara::dbus::kThrusterIface);
        out.push_back(!get(p, "Online").boolean() ? 2 : get(p, "Faults").items.empty() ? 0 : 1);
    }
    const std::string bus = get(props(caracara::dbus::kBusPath, caracara::dbus::kBusIface), "State").s;
    out.push_back(bus == "lost" ? 2 : bus == "ok" ? 0 : 1);
    out.push_back(get(props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Online").boolean() ? 0 : 2);
    const Props& v = props(kRoot, caracara::dbus::kVehicleIface);
    out.push_back(get(v, "Failsafes").items.empty() ? 0 : 1);
    const std::string state = get(v, "State").s;
    out.push_back(state == "fault" ? 2 : state == "ready" || state == "arming" ? 0 : 1);
    // The ROS commands: WARN while a refusal is recent, so a monitor shows it, then OK again.
    const uint64_t last = commands_.last_refusal_ns();
    out.push_back(last && monotonic_ns() < last + kRefusalWarnNs ? 1 : 0);
    // The distro: WARN while peers of both are about (some of them cannot read what is sent).
    out.push_back(detector_ && detector_->peers(RangeLayout::Humble) && detector_->peers(RangeLayout::Jazzy) ? 1 : 0);
    out.push_back(range_subscribers_.warn() ? 1 : 0); // a Range subscriber cannot read what is written
    return out;
}

void TelemetryPublisher::write_diagnostics() {
    struct Status {
        uint8_t level;
        std::string name, message, hardware_id;
        std::vector<std::pair<std::string, std::string>> values;
    };
    static const char* const kLevel[] = {"OK", "WARN", "ERROR"};
    const std::vector<uint8_t> lv = levels();
    std::vector<Status> st;
    const auto num = [](const Value& v) {
        char b[32];
        std::snprintf(b, sizeof b, "%g", v.number());
        return std::string(b);
    };
    for (unsigned i = 0; i < kThrusters; ++i) {
        const Props& p = props(kThrusterPrefix + std::to_string(i), caracara::dbus::kThrusterIface);
        std::string faults;
        for (const Value& f : get(p, "Faults").items)
            faults += (faults.empty() ? "" : ",") + f.s;
        st.push_back({lv[i], "caracara: " + thruster_joint_name(i),
                      lv[i] == 2 ? "unreachable" : faults.empty() ? "ok" : "faults: " + faults,
                      "seabotix@0x" + [&] { char b[8]; std::snprintf(b, sizeof b, "%02x", static_cast<unsigned>(get(p, "Address").unsigned_integer())); return std::string(b); }(),
                      {{"ordered value", std::to_string(get(p, "OrderedValue").integer())},
                       {"actual speed", std::to_string(get(p, "ActualSpeed").unsigned_integer())},
                       {"current A", num(get(p, "Current"))}, {"temperature C", num(get(p, "Temperature"))},
                       {"faults", faults}, {"orders sent", std::to_string(get(p, "OrdersSent").unsigned_integer())},
                       {"order failures", std::to_string(get(p, "OrderFailures").unsigned_integer())},
                       {"last error", get(p, "LastError").s}}});
    }
    const Props& b = props(caracara::dbus::kBusPath, caracara::dbus::kBusIface);
    st.push_back({lv[kThrusters], "caracara: i2c bus", get(b, "State").s, get(b, "Device").s,
                  {{"transactions", std::to_string(get(b, "Transactions").unsigned_integer())},
                   {"errors", std::to_string(get(b, "Errors").unsigned_integer())},
                   {"recoveries", std::to_string(get(b, "Recoveries").unsigned_integer())},
                   {"last error", get(b, "LastError").s}}});
    const Props& t = props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface);
    st.push_back({lv[kThrusters + 1], "caracara: teensy", get(t, "Online").boolean() ? "online" : "offline", "teensy",
                  {{"frames", std::to_string(get(t, "Frames").unsigned_integer())},
                   {"busy retries", std::to_string(get(t, "BusyRetries").unsigned_integer())},
                   {"link errors", std::to_string(get(t, "LinkErrors").unsigned_integer())}}});
    const Props& v = props(kRoot, caracara::dbus::kVehicleIface);
    Status fs{lv[kThrusters + 2], "caracara: failsafes", "", "caracarad", {}};
    for (const Value& f : get(v, "Failsafes").items) // (condition, action, thruster)
        if (f.items.size() == 3)
            fs.values.push_back({f.items[0].s, f.items[1].s + (f.items[2].integer() >= 0 ? " thruster " + std::to_string(f.items[2].integer()) : "")});
    fs.message = fs.values.empty() ? "none active" : std::to_string(fs.values.size()) + " active";
    st.push_back(std::move(fs));
    st.push_back({lv[kThrusters + 3], "caracara: vehicle", get(v, "State").s, "caracarad",
                  {{"kill source", get(v, "KillSource").s}, {"profile", get(v, "Profile").s},
                   {"controller", get(v, "Controller").s}, {"budget limit", std::to_string(get(v, "BudgetLimit").integer())}}});
    const uint64_t now = monotonic_ns();
    const std::string holder = commands_.holder(now);
    Status cs{lv[kThrusters + 4], "caracara: ros commands",
              !config_.commands ? "off (kill only)" : holder.empty() ? "no writer holds the vehicle" : "held by writer " + holder,
              "caracara-ros",
              {{"holder", holder}, {"command timeout ms", std::to_string(commands_.timeout_ms())},
               {"refused", std::to_string(commands_.refusals())}}};
    for (const auto& n : EnumNames<CommandRefusal>::table)
        cs.values.push_back({"refused " + std::string(n.name), std::to_string(commands_.refusals(n.value))});
    cs.values.push_back({"last refusal", commands_.last_refusal()});
    st.push_back(std::move(cs));
    const auto peers = [&](RangeLayout d) { return detector_ ? std::to_string(detector_->peers(d)) : std::string("not read"); };
    st.push_back({lv[kThrusters + 5], "caracara: ros distro", std::string(name_of(distro_.layout)) + ": " + distro_.why,
                  "caracara-ros",
                  {{"speaking", std::string(name_of(distro_.layout))}, {"why", distro_.why},
                   {"humble peers", peers(RangeLayout::Humble)}, {"jazzy peers", peers(RangeLayout::Jazzy)}}});
    st.push_back({lv[kThrusters + 6], "caracara: ros range layout",
                  std::string(name_of(range_subscribers_.layout())) + ": " + range_subscribers_.why(), "caracara-ros",
                  range_subscribers_.values()});
    std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>> kvs(st.size());
    std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> out;
    for (std::size_t i = 0; i < st.size(); ++i) {
        for (auto& [k, val] : st[i].values)
            kvs[i].push_back({c_str(k), c_str(val)});
        const auto n = static_cast<uint32_t>(kvs[i].size());
        out.push_back({st[i].level, c_str(st[i].name), c_str(st[i].message), c_str(st[i].hardware_id),
                       {n, n, kvs[i].data(), false}});
    }
    const auto n = static_cast<uint32_t>(out.size());
    static const std::string kNoFrame; // diagnostics have no frame; header() keeps a pointer into it
    diagnostic_msgs_msg_dds__DiagnosticArray_ a{header(kNoFrame), {n, n, out.data(), false}};
    dds_write(diagnostics_, &a);
    if (lv != last_levels_)
        for (std::size_t i = 0; i < lv.size() && i < st.size(); ++i)
            if (last_levels_.size() != lv.size() || last_levels_[i] != lv[i])
                std::fprintf(stderr, "caracara-ros: %s: %s (%s)\n", st[i].name.c_str(), kLevel[lv[i]], st[i].message.c_str());
    last_levels_ = lv;
}

} // namespace caracara::ros
