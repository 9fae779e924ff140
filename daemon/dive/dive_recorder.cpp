#include "daemon/dive/dive_recorder.hpp"

#include "core/clock.hpp"
#include "drivers/platform/dive_files.hpp"

#include <algorithm>
#include <chrono>
#include <cstddef>

namespace caracara {

namespace {
constexpr uint64_t kFlushPeriodNs = 1'000'000'000; // a crash loses at most this much
// A block is also handed over once this much is buffered: the loop's rate sets how much a
// second holds (loop_rate_hz = 0: thousands of samples, megabytes a second), and the buffer,
// its sealed copy and the writer's queue would grow with it, past the format's 4 MiB block
// on a fast machine. At 50 Hz a second holds about 11 KB, so only the period applies.
constexpr std::size_t kFlushBytes = 64 * 1024;
constexpr uint64_t kNsPer100us = 100'000;

uint64_t unix_ms() {
    using namespace std::chrono;
    return static_cast<uint64_t>(duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count());
}
} // namespace

DiveRecorder::DiveRecorder(const DaemonConfig& config, const Vehicle& vehicle, const ThrusterBus& bus,
                           const TeensyPort& teensy, const VehicleEvents& events, DiveWriter& writer,
                           const MotorTest& motor_test, const DirectionDetection& detection)
    : config_(config), vehicle_(vehicle), bus_(bus), events_(events), writer_(writer), sampler_(vehicle, bus, teensy),
      commissioning_(vehicle, motor_test, detection) {}

void DiveRecorder::start() {
    started_ = true;
    const SafetyState s = vehicle_.readings().safety().state();
    if (s == SafetyState::Arming || s == SafetyState::Ready)
        begin(monotonic_ns(), "start");
}

void DiveRecorder::stop() {
    if (recording_)
        finish(monotonic_ns(), "stopped");
    started_ = false;
}

uint32_t DiveRecorder::since_start(uint64_t now_ns) const {
    const uint64_t t = elapsed(start_ns_, now_ns) / kNsPer100us;
    return static_cast<uint32_t>(std::min<uint64_t>(t, UINT32_MAX));
}

void DiveRecorder::begin(uint64_t now_ns, const char* reason) {
    recording_ = true;
    start_ns_ = now_ns;
    last_flush_ns_ = now_ns;
    records_.clear();
    const uint64_t wall = unix_ms();
    dive::Header h;
    h.start_unix_ms = wall;
    h.start_mono_ns = now_ns;
    h.loop_rate_hz = config_.control.loop_rate_hz;
    h.profile = vehicle_.readings().profile().name;
    h.reason = reason;
    writer_.open(dive_file_name(wall), dive::encode_header(h));
    for (std::size_t i = 0; i < faults_.size() && i < bus_.size(); ++i)
        faults_[i] = bus_.health().faults(i).bits;
    commissioning_.reset();
    // The state it starts in, with who asked for it.
    dive::Event e;
    e.kind = dive::EventKind::State;
    e.state = static_cast<uint8_t>(vehicle_.readings().safety().state());
    e.client = events_.caller();
    e.text = reason;
    add_event(std::move(e), now_ns);
}

void DiveRecorder::finish(uint64_t now_ns, const std::string& reason) {
    commissioning_.close(records_, since_start(now_ns));
    dive::encode_sample(records_, sampler_.sample(since_start(now_ns))); // the zeros the dive ends with
    dive::encode_end(records_, {since_start(now_ns), reason});
    flush();
    writer_.close();
    recording_ = false;
}

void DiveRecorder::flush() {
    if (!records_.empty())
        writer_.append(dive::seal_block(records_));
    records_.clear();
}

void DiveRecorder::add_event(dive::Event e, uint64_t now_ns) {
    e.t_100us = since_start(now_ns);
    dive::encode_event(records_, e);
}

void DiveRecorder::vehicle_changed(uint32_t changes) {
    if (!started_)
        return;
    const uint64_t now = monotonic_ns();
    const SafetyState s = vehicle_.readings().safety().state();
    const bool driving = s == SafetyState::Arming || s == SafetyState::Ready;
    if ((changes & kChangeState) && !recording_ && driving) {
        begin(now, "clear-kill");
        return;
    }
    if (!recording_)
        return;
    if (changes & kChangeState) {
        dive::Event e;
        e.kind = dive::EventKind::State;
        e.state = static_cast<uint8_t>(s);
        e.kill_source = static_cast<uint8_t>(s == SafetyState::Killed ? vehicle_.readings().safety().kill_record().source : KillSource::None);
        e.text = s == SafetyState::Killed ? vehicle_.readings().safety().kill_record().reason : std::string();
        e.client = events_.caller();
        add_event(std::move(e), now);
    }
    if (changes & kChangeFaults) {
        for (std::size_t i = 0; i < faults_.size() && i < bus_.size(); ++i) {
            const uint8_t bits = bus_.health().faults(i).bits;
            if (bits == faults_[i])
                continue;
            faults_[i] = bits;
            dive::Event e;
            e.kind = dive::EventKind::Fault;
            e.thruster = static_cast<uint8_t>(i);
            e.value = bits;
            e.text = format_faults(FaultSet{bits});
            add_event(std::move(e), now);
        }
    }
    if (changes & kChangeProfile)
        add_event({0, dive::EventKind::Profile, 0, 0, 0, 0, static_cast<float>(vehicle_.readings().profile().factor),
                   vehicle_.readings().profile().name, events_.caller()}, now);
    if ((changes & kChangeState) && !driving)
        finish(now, s == SafetyState::PoweredOff ? "powered-off"
                                                 : "killed (" + std::string(vehicle_.readings().kill_source_name()) + ")");
}

void DiveRecorder::failsafe(const ActiveFailsafe& f, bool raised) {
    if (!recording_)
        return;
    dive::Event e;
    e.kind = dive::EventKind::Failsafe;
    e.thruster = static_cast<uint8_t>(f.thruster < 0 ? 0 : f.thruster);
    e.value = (raised ? dive::kFailsafeRaised : 0u) | (f.thruster < 0 ? dive::kFailsafeVehicle : 0u);
    e.text = std::string(condition_name(f.condition)) + " " + std::string(action_name(f.effective()));
    add_event(std::move(e), monotonic_ns());
}

void DiveRecorder::motor_test(int32_t thruster, int32_t value) {
    if (recording_)
        commissioning_.motor_test(records_, since_start(monotonic_ns()), thruster, value);
}

void DiveRecorder::bus_lost(const std::string& reason) {
    if (!recording_)
        return;
    add_event({0, dive::EventKind::BusLost, 0, 0, 0, 0, 0, reason, ""}, monotonic_ns());
}

void DiveRecorder::bus_restored(uint32_t pulses, double milliseconds) {
    if (!recording_)
        return;
    add_event({0, dive::EventKind::BusRestored, 0, 0, 0, pulses, static_cast<float>(milliseconds), "", ""},
              monotonic_ns());
}

void DiveRecorder::cycle(uint64_t now_ns) {
    if (!recording_)
        return;
    commissioning_.record(records_, since_start(now_ns));
    dive::encode_sample(records_, sampler_.sample(since_start(now_ns)));
    if (now_ns - last_flush_ns_ >= kFlushPeriodNs || records_.size() >= kFlushBytes) {
        last_flush_ns_ = now_ns;
        flush();
    }
}

} // namespace caracara
