#include "tools/foxglove/dive_mcap.hpp"

#include "core/direction_judgement.hpp"
#include "core/safety.hpp"
#include "tools/foxglove/channels.hpp"
#include "tools/foxglove/mcap_writer.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace caracara::foxglove {

namespace dive = caracara::dive;

namespace {

const char* const kBusStates[] = {"ok", "recovering", "lost", "lost"};

// The foxglove.Log of a dive event; the vehicle state it leaves in `state`.
LogEvent log_of(const dive::Event& e, uint64_t time_ns, VehicleState& state) {
    LogEvent log{time_ns, LogLevel::Info, std::string(dive::event_kind_name(e.kind)), {}};
    switch (e.kind) {
    case dive::EventKind::State: {
        const auto s = static_cast<SafetyState>(e.state);
        state.state = std::string(state_name(s));
        state.kill_source = s == SafetyState::Killed ? std::string(kill_source_name(static_cast<KillSource>(e.kill_source))) : "";
        log.name = s == SafetyState::Killed ? "kill" : s == SafetyState::Arming ? "arming" : "state";
        log.level = s == SafetyState::Killed || s == SafetyState::PoweredOff ? LogLevel::Warning : LogLevel::Info;
        log.message = state.state + (state.kill_source.empty() ? "" : " (" + state.kill_source + ")") +
                      (e.text.empty() ? "" : ": " + e.text) + (e.client.empty() ? "" : " by " + e.client);
        break;
    }
    case dive::EventKind::Fault:
        log.level = e.value ? LogLevel::Error : LogLevel::Info;
        log.message = "thruster " + std::to_string(e.thruster) + " faults: " + (e.text.empty() ? "none" : e.text);
        break;
    case dive::EventKind::BusLost:
        log.level = LogLevel::Error;
        log.message = "I2C bus lost: " + e.text;
        break;
    case dive::EventKind::BusRestored: {
        char text[96];
        std::snprintf(text, sizeof text, "I2C bus restored after %u SCL pulses in %.1f ms", e.value,
                      static_cast<double>(e.number));
        log.message = text;
        break;
    }
    case dive::EventKind::Failsafe: {
        // The same words as the live bridge's log of the Failsafe signal (tools/bridge/telemetry.cpp).
        const auto space = e.text.find(' ');
        const std::string condition = e.text.substr(0, space);
        const std::string action = space == std::string::npos ? "" : e.text.substr(space + 1);
        const bool raised = e.value & dive::kFailsafeRaised;
        const int64_t thruster = e.value & dive::kFailsafeVehicle ? -1 : int64_t{e.thruster};
        std::erase_if(state.failsafes,
                      [&](const ActiveFailsafe& f) { return f.condition == condition && f.thruster == thruster; });
        if (raised)
            state.failsafes.push_back({condition, action, thruster});
        log.name = "failsafe";
        log.level = raised ? LogLevel::Warning : LogLevel::Info;
        log.message = condition + " -> " + action +
                      (e.value & dive::kFailsafeVehicle ? "" : " (thruster " + std::to_string(e.thruster) + ")") +
                      (raised ? "" : " cleared");
        break;
    }
    case dive::EventKind::Profile:
        state.profile = e.text;
        state.profile_factor = e.number;
        log.message = "profile " + e.text;
        break;
    case dive::EventKind::MotorTest:
    case dive::EventKind::DetectionPulse: {
        const bool on = e.value & dive::kOn;
        char text[96];
        std::snprintf(text, sizeof text, on ? "%s: thruster %u at %.0f" : "%s: thruster %u stopped",
                      e.kind == dive::EventKind::MotorTest ? "motor test" : "detection pulse", e.thruster,
                      static_cast<double>(e.number));
        log.message = text;
        break;
    }
    case dive::EventKind::Detection:
        log.message = e.value & dive::kOn ? "direction detection started"
                                          : "direction detection ended, " + std::to_string(int(e.number)) +
                                                " thrusters judged";
        break;
    case dive::EventKind::DetectionResult:
        log.level = static_cast<DirectionVerdict>(e.value) == DirectionVerdict::Ok ? LogLevel::Info : LogLevel::Warning;
        log.message = "direction detection: thruster " + std::to_string(e.thruster) + " " +
                      std::string(verdict_name(static_cast<DirectionVerdict>(e.value))) + " (" + e.text + ")";
        break;
    }
    return log;
}

} // namespace

std::vector<uint8_t> dive_to_mcap(const dive::Dive& d) {
    McapWriter w("", "caracaractl export");
    std::vector<uint16_t> ids;
    for (const ChannelInfo& c : channels())
        ids.push_back(w.add_channel(w.add_schema(c.schema_name, kSchemaEncoding, c.schema), c.topic, kEncoding));
    auto id = [&](ChannelKind k, unsigned i = 0) { return ids[channel_position(k, i)]; };
    const uint64_t start_ns = d.header.start_unix_ms * 1'000'000u;
    auto at = [&](uint32_t t_100us) { return start_ns + uint64_t{t_100us} * 100'000u; };

    VehicleState state{"arming", "", d.header.profile, 1.0, 0, false, -1, "", "", {}, {}, -1};
    std::size_t next_event = 0;
    uint64_t surfacing_since = 0; // when the ascent of a surface failsafe began; 0 none
    auto events_until = [&](uint32_t t) {
        for (; next_event < d.events.size() && d.events[next_event].t_100us <= t; ++next_event) {
            const uint64_t ns = at(d.events[next_event].t_100us);
            w.add_message(id(ChannelKind::Events), ns, ns, to_json(log_of(d.events[next_event], ns, state)));
            const bool surfacing = state.state != "killed" && state.state != "powered-off" &&
                                   std::ranges::any_of(state.failsafes, [](const ActiveFailsafe& f) { return f.action == "surface"; });
            surfacing_since = surfacing ? (surfacing_since ? surfacing_since : ns) : 0;
        }
    };
    for (const dive::Sample& s : d.samples) {
        const uint64_t ns = at(s.t_100us);
        events_until(s.t_100us);
        auto put = [&](uint16_t channel, const std::string& json) { w.add_message(channel, ns, ns, json); };
        state.budget_limit = s.budget_limit;
        state.saturated = s.flags & dive::kSaturated;
        state.surfacing_ms = surfacing_since ? static_cast<int64_t>((ns - surfacing_since) / 1'000'000u) : -1;
        put(id(ChannelKind::VehicleState), to_json(state));
        Motors m;
        for (std::size_t i = 0; i < kThrusters; ++i) {
            m.applied[i] = s.applied[i];
            m.requested[i] = s.requested[i];
        }
        put(id(ChannelKind::Motors), to_json(m));
        for (unsigned i = 0; i < kThrusters; ++i) {
            const dive::ThrusterSample& t = s.thrusters[i];
            Thruster th;
            th.index = i;
            th.reachable = t.flags & dive::kOnline;
            th.speed = t.speed == dive::kUnknownSpeed ? 0 : t.speed;
            th.ordered_value = s.applied[i];
            th.current = (t.flags & dive::kCurrentKnown) ? t.current_da / 10.0 : 0.0;
            th.temperature = t.temperature_c;
            th.fault_bits = t.faults;
            th.faults = fault_names(t.faults);
            put(id(ChannelKind::Thruster, i), to_json(th));
        }
        Teensy teensy;
        teensy.online = s.flags & dive::kTeensyOnline;
        teensy.yaw = s.orientation[0];
        teensy.pitch = s.orientation[1];
        teensy.roll = s.orientation[2];
        teensy.distances.assign(s.distances.begin(), s.distances.end());
        put(id(ChannelKind::Teensy), to_json(teensy));
        I2cBus bus;
        bus.state = kBusStates[s.bus_state()];
        bus.errors = s.bus_errors;
        bus.recoveries = s.bus_recoveries;
        put(id(ChannelKind::I2cBus), to_json(bus));
        put(id(ChannelKind::Attitude), attitude_json(ns, s.orientation[0], s.orientation[1], s.orientation[2]));
    }
    events_until(UINT32_MAX);
    if (d.ended) {
        // What closed the dive, as caracaractl export --events lists it last.
        const uint64_t ns = at(d.end.t_100us);
        w.add_message(id(ChannelKind::Events), ns, ns, to_json(LogEvent{ns, LogLevel::Info, "end", "dive ended: " + d.end.reason}));
    }
    return w.finish();
}

} // namespace caracara::foxglove
