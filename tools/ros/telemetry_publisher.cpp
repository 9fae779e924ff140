#include "tools/ros/telemetry_publisher.hpp"

#include "core/clock.hpp"
#include "core/frames.hpp"
#include "drivers/protocol/seabotix.hpp"
#include "tools/ros/mirror_values.hpp"
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
constexpr unsigned kThrusters = kThrusterJoints;
constexpr uint64_t kDiagnosticsPeriodUs = 1'000'000; // a diagnostics monitor's expectation: about 1 Hz

int thruster_of(const std::string& path) {
    if (!path.starts_with(kThrusterPathPrefix) || path.size() != kThrusterPathPrefix.size() + 1)
        return -1;
    const int n = path.back() - '0';
    return n >= 0 && n < static_cast<int>(kThrusters) ? n : -1;
}

// The thruster's reported SPEED byte as a fraction of full thrust (-1..1), 0 when unknown.
double actual_fraction(const Props& p) {
    const auto m = caracara::speed_to_motor(static_cast<uint8_t>(prop(p, "ActualSpeed").unsigned_integer()));
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
      diagnostics_(dds, mirror_, config, commands, distro, detector_.get(), range_subscribers_),
      static_frames_(dds, config),
      jazzy_range_(under_type_name(jazzy_sensor_msgs_msg_dds__Range__desc, "sensor_msgs::msg::dds_::Range_")) {
    commands_.on_change([this] { mark(kDiagnostics); }); // a refusal on /diagnostics within a second
    const auto topic = [&](const char* name) { return ros_topic(config_, name); };
    imu_ = dds_.writer(&sensor_msgs_msg_dds__Imu__desc, topic("imu"), Profile::Default);
    if (config_.publish_odom_tf) // else no writer at all: ros2 topic info /tf names only the localization's
        tf_ = dds_.writer(&tf2_msgs_msg_dds__TFMessage__desc, "/tf", Profile::Default);
    joints_ = dds_.writer(&sensor_msgs_msg_dds__JointState__desc, topic("joint_states"), Profile::Default);
    ordered_ = dds_.writer(&sensor_msgs_msg_dds__JointState__desc, topic("thrusters/ordered"), Profile::Default);
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
    if (!static_frames_.written()) // the config's sensors at once; the Teensy's others when it reports them
        static_frames_.write(ranges_.size());
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
    commands_.set_timeout_ms(prop(props(kRoot, caracara::dbus::kVehicleIface), "CommandTimeoutMs").unsigned_integer());
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
    commands_.set_timeout_ms(prop(props(kRoot, caracara::dbus::kVehicleIface), "CommandTimeoutMs").unsigned_integer());
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
    const uint64_t read_ns = prop(changes, "OrientationReadNs").unsigned_integer();
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
        if (self->diagnostics_.level_changed() || now >= self->diagnostics_last_us_ + kDiagnosticsPeriodUs) {
            self->diagnostics_timer_.reset();
            self->diagnostics_.write();
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
    self->diagnostics_.write();
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
    if (prop(self->props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Online").boolean())
        self->write_imu_and_tf();
    self->write_joints();
    return 0;
}

void TelemetryPublisher::write_state() {
    const Props& p = props(kRoot, caracara::dbus::kVehicleIface);
    const std::string state = prop(p, "State").s, source = prop(p, "KillSource").s;
    if (state_written_ && state == last_state_ && source == last_source_)
        return; // latched topics carry changes only
    std_msgs_msg_dds__Bool_ killed{state_is_killed(state)};
    dds_write(killed_, &killed);
    std_msgs_msg_dds__String_ s{msg_str(state)};
    dds_write(state_, &s);
    std_msgs_msg_dds__String_ k{msg_str(source)};
    dds_write(kill_source_, &k);
    last_state_ = state;
    last_source_ = source;
    state_written_ = true;
}

void TelemetryPublisher::write_imu_and_tf() {
    const Value& o = prop(props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Orientation");
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
    t.child_frame_id = msg_str(body_frame_);
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
        const Props& p = props(kThrusterPathPrefix + std::to_string(i), caracara::dbus::kThrusterIface);
        names.push_back(thruster_joint_name(i));
        actual.push_back(actual_fraction(p));
        current.push_back(prop(p, "Current").number());
        ordered.push_back(motor_fraction(static_cast<int32_t>(prop(p, "OrderedValue").integer())));
    }
    for (auto& n : names)
        name_ptrs.push_back(msg_str(n));
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
    const Value& d = prop(props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Distances");
    const bool more = d.items.size() > ranges_.size();
    for (std::size_t i = ranges_.size(); i < d.items.size(); ++i)
        ranges_.push_back(dds_.writer(range_subscribers_.layout() == RangeLayout::Jazzy ? &jazzy_range_ : &sensor_msgs_msg_dds__Range__desc,
                                      ros_topic(config_, "range/" + std::to_string(i)), Profile::Default));
    if (more && d.items.size() > config_.ranges.size())
        static_frames_.write(ranges_.size()); // a sensor the config does not list: its frame, at the origin
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
    const RangeLayout before = distro_.layout;
    if (!detector_->choose(distro_))
        return; // the last peer left: what it spoke stays until another says otherwise
    std::fprintf(stderr, "caracara-ros: speaking %s: %s\n", std::string(name_of(distro_.layout)).c_str(),
                 distro_.why.c_str());
    mark(kDiagnostics);
    if (distro_.layout != before) // ros_discovery_info's Gid; Range's layout follows in range_subscribers_
        dds_.discovery_info().set_layout(distro_.layout);
}

} // namespace caracara::ros
