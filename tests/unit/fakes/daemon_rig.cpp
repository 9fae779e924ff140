#include "tests/unit/fakes/daemon_rig.hpp"

#include "core/clock.hpp"
#include "core/safety.hpp"
#include "drivers/protocol/seabotix.hpp"

#include <stdexcept>

namespace caracara::test {

namespace {
DaemonConfig parse(const std::string& control, const std::string& sections) {
    const std::string arm = control.find("arm_at_start") == std::string::npos ? "arm_at_start = true\n" : "";
    // The fakes have no Teensy: not fitted, unless the test's own [spi] says it is.
    const std::string spi = sections.find("[spi]") == std::string::npos ? "[spi]\nfitted = false\n" : "";
    // The recorder off, unless the test's own [recorder] says otherwise.
    const std::string recorder = sections.find("[recorder]") == std::string::npos ? "[recorder]\nenabled = false\n" : "";
    ConfigResult r = parse_config_string("[control]\n" + arm + "arming_delay_ms = 0\n" + control +
                                             FakeGpio::config_section() + recorder + spi +
                                             // The test runner's own thread is the loop here: not at a real-time policy.
                                             "[realtime]\nenabled = false\n" + sections,
                                         "the test rig");
    if (!r.ok())
        throw std::runtime_error(r.error());
    return *r.config;
}
} // namespace

DaemonRig::DaemonRig(const std::string& control, const std::string& sections, bool kill_switch_set, DeviceIo* spi_io)
    : config_(parse(control, sections)), io_(wire_, config_), gpio_(wire_) {
    gpio_.set_kill_switch(kill_switch_set); // before the daemon reads it
    if (sd_event_new(&event_) < 0)
        throw std::runtime_error("sd_event_new");
    daemon_ = std::make_unique<VehicleDaemon>(event_, io_, io_, spi_io ? *spi_io : io_, gpio_, config_);
    if (std::string e = daemon_->start(); !e.empty())
        throw std::runtime_error(e);
}

DaemonRig::~DaemonRig() {
    daemon_.reset();
    sd_event_unref(event_);
}

bool DaemonRig::run_until(const std::function<bool()>& done, int timeout_ms) {
    const uint64_t end = monotonic_ns() + ms_to_ns(static_cast<uint64_t>(timeout_ms));
    while (!done() && monotonic_ns() < end)
        sd_event_run(event_, 10'000);
    return done();
}

void DaemonRig::run_for(int ms) {
    run_until([] { return false; }, ms);
}

void DaemonRig::run_until_ready() {
    const bool ready = run_until([&] {
        if (!vehicle().readings().may_drive())
            return false;
        const auto ev = wire_.events();
        for (std::size_t i = 0; i < config_.thrusters.size(); ++i)
            if (find(ev, [i](const WireEvent& e) { return e.kind == WireEvent::Kind::Order && e.thruster == i; }) < 0)
                return false;
        return true;
    });
    if (!ready)
        throw std::runtime_error("the vehicle did not become ready");
}

int32_t on_wire(int32_t v) {
    return speed_to_motor(*motor_to_speed(v)).value_or(0);
}

long find(const std::vector<WireEvent>& events, const std::function<bool(const WireEvent&)>& match, long from) {
    for (long i = from; i < static_cast<long>(events.size()); ++i)
        if (match(events[static_cast<std::size_t>(i)]))
            return i;
    return -1;
}

bool each_ordered(const std::vector<WireEvent>& events, const std::vector<int32_t>& values, long from) {
    for (std::size_t i = 0; i < values.size(); ++i)
        if (find(events, [&](const WireEvent& e) { return e.is_order(i, on_wire(values[i])); }, from) < 0)
            return false;
    return true;
}

bool all_zeroed(const std::vector<WireEvent>& events, long from) {
    return each_ordered(events, std::vector<int32_t>(kMotorCount, 0), from);
}

long kill_output(const std::vector<WireEvent>& events, int value, long from) {
    return find(events, [&](const WireEvent& e) { return e.kind == WireEvent::Kind::KillOutput && e.value == value; },
                from);
}

} // namespace caracara::test
