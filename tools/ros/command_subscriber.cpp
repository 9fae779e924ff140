#include "tools/ros/command_subscriber.hpp"

#include "core/clock.hpp"
#include "core/frames.hpp"
#include "core/motor.hpp"
#include "tools/ros/gid_text.hpp"

#include <cmath>
#include <cstdio>
#include <ros_msgs.h>
#include <set>
#include <stdexcept>
#include <sys/eventfd.h>
#include <unistd.h>

namespace caracara::ros {

namespace {

constexpr int kBatch = 16;
// Takes all that `reader` holds, a batch at a time, and hands each valid sample with its writer to `use`.
template <typename T, typename Use>
void take_each(dds_entity_t reader, Use use) {
    for (dds_return_t n = kBatch; n == kBatch;) {
        void* samples[kBatch] = {};
        dds_sample_info_t info[kBatch];
        n = dds_take(reader, samples, info, kBatch, kBatch);
        for (dds_return_t i = 0; i < n; ++i)
            if (info[i].valid_data)
                use(*static_cast<const T*>(samples[i]), info[i].publication_handle);
        if (n > 0)
            dds_return_loan(reader, samples, n);
    }
}

// A refused Wrench is named in SetMotion's (the seed's) axes: the log says which Wrench field
// each is, read off core/frames' conversion ("x = force.y, ..., roll = torque.x").
std::string wrench_axes_note() {
    static const char* const kFields[] = {"force.x", "force.y", "force.z", "torque.x", "torque.y", "torque.z"};
    std::string note = "cmd_wrench in SetMotion's axes:";
    for (std::size_t axis = 0; axis < caracara::kAxisCount; ++axis)
        for (std::size_t k = 0; k < 6; ++k) {
            frames::BodyMotion unit;
            frames::Vec3& v = k < 3 ? unit.linear : unit.angular;
            (k % 3 == 0 ? v.x : k % 3 == 1 ? v.y : v.z) = 1;
            if (const double sign = frames::from_flu(unit)[axis]; sign != 0)
                note += std::string(axis == 0 ? " " : ", ") + std::string(caracara::axis_name(axis)) + " = " +
                        (sign < 0 ? "-" : "") + kFields[k];
        }
    return note;
}

} // namespace

CommandSubscriber::CommandSubscriber(sd_event* event, DdsParticipant& dds, const RosConfig& config,
                                     CommandRecord& record, const SpokenDistro& distro, std::function<void()> kill)
    : event_(event), config_(config), distro_(distro), kill_(std::move(kill)), record_(record) {
    wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    sd_event_source* s = nullptr;
    if (wake_fd_ < 0 || sd_event_add_io(event_, &s, wake_fd_, EPOLLIN, on_wake, this) < 0)
        throw std::runtime_error("cannot make the command wake-up");
    wake_.reset(s);
    // Above D-Bus: a kill never waits behind telemetry.
    sd_event_source_set_priority(s, SD_EVENT_PRIORITY_IMPORTANT);
    listener_ = dds_create_listener(this);
    dds_lset_data_available(listener_, on_dds);
    dds_lset_publication_matched(listener_, on_matched);
    // Kill: reliable, as `ros2 topic pub` sends by default.
    kill_reader_ = dds.reader(&std_msgs_msg_dds__Empty__desc, ros_topic(config_, "kill"), Profile::Default, listener_);
    if (config_.commands) {
        // Best-effort readers match both reliable and best-effort writers.
        wrench_reader_ = dds.reader(&geometry_msgs_msg_dds__Wrench__desc, ros_topic(config_, "cmd_wrench"),
                                    Profile::SensorReader, listener_);
        thrust_reader_ = dds.reader(&std_msgs_msg_dds__Float64MultiArray__desc, ros_topic(config_, "cmd_thrust"),
                                    Profile::SensorReader, listener_);
    }
    // Under DDS Security, every command topic (the kill's too: it follows the same governance)
    // only from writers whose signed permissions allow it.
    try {
        for (const char* name : {"kill", "cmd_wrench", "cmd_thrust"})
            if (config_.commands || std::string(name) == "kill")
                dds.require_protected(ros_topic(config_, name));
    } catch (...) {
        release(); // no destructor runs for a constructor that throws: Cyclone must not call into it
        throw;
    }
}

CommandSubscriber::~CommandSubscriber() { release(); }

void CommandSubscriber::release() {
    for (const dds_entity_t r : {kill_reader_, wrench_reader_, thrust_reader_})
        if (r > 0)
            dds_set_listener(r, nullptr);
    dds_delete_listener(listener_);
    listener_ = nullptr;
    wake_.reset();
    if (wake_fd_ >= 0)
        close(wake_fd_);
    wake_fd_ = -1;
}

void CommandSubscriber::on_dds(dds_entity_t, void* arg) {
    const uint64_t one = 1;
    [[maybe_unused]] const auto n = write(static_cast<CommandSubscriber*>(arg)->wake_fd_, &one, sizeof one);
}

void CommandSubscriber::on_matched(dds_entity_t reader, const dds_publication_matched_status_t, void* arg) {
    on_dds(reader, arg);
}

int CommandSubscriber::on_wake(sd_event_source*, int fd, uint32_t, void* userdata) {
    uint64_t count = 0;
    [[maybe_unused]] const auto n = read(fd, &count, sizeof count);
    static_cast<CommandSubscriber*>(userdata)->drain();
    return 0;
}

void CommandSubscriber::drain() {
    take_kills();
    if (!config_.commands)
        return;
    take_wrenches();
    take_thrusts();
    drop_unmatched();
}

void CommandSubscriber::take_kills() {
    bool any = false;
    take_each<std_msgs_msg_dds__Empty_>(kill_reader_, [&](const auto&, dds_instance_handle_t) { any = true; });
    if (any) {
        std::fprintf(stderr, "caracara-ros: kill from DDS\n");
        kill_();
    }
}

const std::string& CommandSubscriber::gid(dds_entity_t reader, dds_instance_handle_t writer) {
    auto [it, added] = gids_.try_emplace(writer);
    if (added) {
        dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(reader, writer);
        if (e) {
            it->second = gid_text(e->key, distro_.layout);
            dds_builtintopic_free_endpoint(e);
        } else { // no longer matched: its instance handle is all there is to name it by
            char b[32];
            std::snprintf(b, sizeof b, "(handle %016llx)", static_cast<unsigned long long>(writer));
            it->second = b;
        }
    }
    return it->second;
}

Pilot* CommandSubscriber::commanding(dds_entity_t reader, dds_instance_handle_t writer, const char* topic) {
    const uint64_t now = monotonic_ns();
    const std::string& name = gid(reader, writer);
    const std::string holder = record_.holder(now);
    if (!holder.empty() && holder_ != writer) {
        const std::string why = "the vehicle is held by writer " + holder + " (until it stops for the command timeout, " +
                                std::to_string(record_.timeout_ms()) + " ms, or leaves)";
        if (told_[writer] != holder_) { // once per hold; /diagnostics counts them all
            std::fprintf(stderr, "caracara-ros: %s from writer %s refused (%s): %s\n", topic, name.c_str(),
                         std::string(name_of(CommandRefusal::NotHolder)).c_str(), why.c_str());
            told_[writer] = holder_;
        }
        record_.refused(name, CommandRefusal::NotHolder, why, now);
        return nullptr;
    }
    if (holder.empty())
        std::fprintf(stderr, "caracara-ros: writer %s holds the vehicle (%s)\n", name.c_str(), topic);
    holder_ = writer;
    record_.commanded(name, now);
    return pilot(writer);
}

Pilot* CommandSubscriber::pilot(dds_instance_handle_t writer) {
    auto& p = pilots_[writer];
    if (!p) {
        const std::string& name = gids_[writer];
        try {
            static const std::string kWrenchNote = wrench_axes_note();
            p = std::make_unique<Pilot>(event_, config_.bus, name, record_, kWrenchNote);
            std::fprintf(stderr, "caracara-ros: writer %s commands as a pilot\n", name.c_str());
        } catch (const std::exception& e) {
            std::fprintf(stderr, "caracara-ros: writer %s: %s\n", name.c_str(), e.what());
            pilots_.erase(writer);
            return nullptr;
        }
    }
    return p.get();
}

void CommandSubscriber::take_wrenches() {
    take_each<geometry_msgs_msg_dds__Wrench_>(wrench_reader_, [&](const auto& w, dds_instance_handle_t writer) {
        // REP 103: the Wrench is in the body's FLU frame (force along, torque about x forward,
        // y left, z up). As fractions, each -1..1 of the axis's full demand: core/frames turns it
        // into the seed's axes SetMotion takes; range and NaN are the daemon's to refuse, by name.
        const frames::BodyMotion flu{{w.force.x, w.force.y, w.force.z}, {w.torque.x, w.torque.y, w.torque.z}};
        Pilot* p = commanding(wrench_reader_, writer, "cmd_wrench");
        if (!p)
            return;
        if (config_.wrench_units == WrenchUnits::Fraction) {
            p->set_motion(frames::from_flu(flu));
            return;
        }
        // Newtons: through the vehicle's geometry and force curve to the eight motor values
        // (SetThrust), where the daemon's budget holds them as it holds any.
        const WrenchMotors m = config_.vehicle.motors_for(flu);
        if (!m.ok()) {
            const std::string& name = gid(wrench_reader_, writer);
            const std::string why = "org.caracara.Vehicle1.Error.InvalidValue: " + m.error;
            std::fprintf(stderr, "caracara-ros: cmd_wrench from writer %s refused: %s\n", name.c_str(), why.c_str());
            record_.refused(name, CommandRefusal::BadValue, why, monotonic_ns());
            return;
        }
        p->set_thrust(std::vector<int32_t>(m.motors.begin(), m.motors.end()));
    });
}

void CommandSubscriber::take_thrusts() {
    take_each<std_msgs_msg_dds__Float64MultiArray_>(thrust_reader_, [&](const auto& a, dds_instance_handle_t writer) {
        // Each value -1..1 of full thrust becomes the motor value round(v * kMotorMax); the daemon
        // refuses a wrong count or a value out of range by name (a value past +-2 is sent as
        // +-2 * kMotorMax, out of range all the same). NaN has no motor value: refused here.
        Pilot* p = commanding(thrust_reader_, writer, "cmd_thrust");
        if (!p)
            return;
        std::vector<int32_t> values;
        for (uint32_t k = 0; k < a.data._length; ++k) {
            const double v = a.data._buffer[k];
            if (!std::isfinite(v)) {
                const std::string& name = gid(thrust_reader_, writer);
                const std::string why = "org.caracara.Vehicle1.Error.InvalidValue: value " + std::to_string(k) +
                                        " is not a number";
                std::fprintf(stderr, "caracara-ros: cmd_thrust from writer %s refused: %s\n", name.c_str(), why.c_str());
                record_.refused(name, CommandRefusal::BadValue, why, monotonic_ns());
                return;
            }
            values.push_back(std::fabs(v) < 2.0 ? static_cast<int32_t>(std::lround(v * caracara::kMotorMax))
                                                : (v > 0 ? 2 : -2) * caracara::kMotorMax);
        }
        p->set_thrust(values);
    });
}

void CommandSubscriber::drop_unmatched() {
    std::set<dds_instance_handle_t> matched;
    for (const dds_entity_t r : {wrench_reader_, thrust_reader_}) {
        dds_instance_handle_t h[64];
        const dds_return_t n = dds_get_matched_publications(r, h, 64);
        for (dds_return_t i = 0; i < n && i < 64; ++i)
            matched.insert(h[i]);
    }
    for (auto it = pilots_.begin(); it != pilots_.end();) {
        if (matched.contains(it->first)) {
            ++it;
            continue;
        }
        const std::string name = gids_[it->first];
        std::fprintf(stderr, "caracara-ros: writer %s gone; its connection closed\n", name.c_str());
        record_.left(name);
        it = pilots_.erase(it);
    }
    // Refused writers have no Pilot: their names go when they do.
    std::erase_if(gids_, [&](const auto& g) { return !matched.contains(g.first); });
    std::erase_if(told_, [&](const auto& t) { return !matched.contains(t.first); });
}

} // namespace caracara::ros
