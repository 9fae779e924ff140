#include "daemon/commissioning/motor_test.hpp"

#include "core/clock.hpp"
#include "daemon/loop/log.hpp"

namespace caracara {

MotorTest::MotorTest(const DaemonConfig& config, Vehicle& vehicle, VehicleEvents& events)
    : config_(config), vehicle_(vehicle), events_(events), keepalive_([this] { expired(); }) {}

std::string MotorTest::start(sd_event* event) { return keepalive_.start(event); }

MotorValues MotorTest::values() const {
    MotorValues m{};
    if (thruster_ >= 0 && thruster_ < static_cast<int32_t>(kMotorCount))
        m[static_cast<size_t>(thruster_)] = value_;
    return m;
}

Result MotorTest::run(int32_t thruster, int32_t value, std::string_view client) {
    const int32_t limit = config_.commissioning.motor_test_limit;
    Result range;
    MotorValues m{};
    if (thruster < 0 || thruster >= static_cast<int32_t>(kMotorCount))
        range = {Status::OutOfRange, "thruster " + std::to_string(thruster) + " is outside 0..7"};
    else if (value < -limit || value > limit)
        range = {Status::OutOfRange, "motor test value " + std::to_string(value) + " is outside -" +
                                         std::to_string(limit) + ".." + std::to_string(limit) +
                                         " (commissioning.motor_test_limit)"};
    else
        m[static_cast<size_t>(thruster)] = value;
    // The same path as SetThrust (CommandAcceptance): state (armed only), this range, the budget;
    // then the commanding client, the wire.
    if (Result r = vehicle_.motors().drive(m, client, range); !r.ok())
        return r;
    events_.motor_test(thruster, value);
    if (!running_ || thruster != thruster_ || client != client_)
        log_notice("motor test: thruster %d at %d for %s", thruster, value, std::string(client).c_str());
    running_ = true;
    thruster_ = thruster;
    value_ = value;
    client_ = client;
    keepalive_.arm(monotonic_ns() + uint64_t(config_.commissioning.motor_test_keepalive_ms) * 1'000'000ull);
    return {};
}

int32_t MotorTest::active_thruster() const {
    if (!running_ || !vehicle_.readings().may_drive() || vehicle_.readings().controller_client() != client_ ||
        vehicle_.readings().requested_values() != values())
        return -1;
    return thruster_;
}

void MotorTest::expired() {
    keepalive_.arm(DeadlineTimer::kNever);
    // Only the test's own command stops here: a pilot's that replaced it goes on.
    if (active_thruster() >= 0) {
        log_notice("motor test: no repeat from %s within %u ms, thruster %d to zero", client_.c_str(),
                   config_.commissioning.motor_test_keepalive_ms, thruster_);
        (void)vehicle_.motors().drive(MotorValues{}, client_);
    }
    running_ = false;
}

} // namespace caracara
