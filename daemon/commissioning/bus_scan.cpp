#include "daemon/commissioning/bus_scan.hpp"

#include "daemon/loop/log.hpp"

namespace caracara {

BusScan::BusScan(const DaemonConfig& config, const Vehicle& vehicle, ThrusterBus& bus)
    : config_(config), vehicle_(vehicle), bus_(bus) {
    // Made once: a step of an ended scan may still be on the worker's thread when the next begins.
    for (const ScanSegment& s : scan_segments(config_.thrusters))
        for (uint8_t mt : scan_addresses(config_.thrusters))
            steps_.push_back({s, mt, false, IoError::None, {}});
    steps_.push_back({std::nullopt, 0, true, IoError::None, {}});
}

void BusScan::run(Completion done) {
    if (running()) {
        done({Status::Busy, "a bus scan is running"});
        return;
    }
    const SafetyState state = vehicle_.readings().safety().state();
    if (state == SafetyState::PoweredOff) {
        done({Status::PoweredOff, "powered off"});
        return;
    }
    if (state != SafetyState::Killed) {
        done({Status::NotKilled, "the vehicle is " + std::string(vehicle_.readings().state_name()) +
                                     ": a bus scan runs only while killed (Kill first), so no order can "
                                     "reach a thruster found where the configuration does not expect it"});
        return;
    }
    if (bus_.monitor().recovering()) {
        done({Status::BusLost, "the I2C bus is being recovered: scan once it is back"});
        return;
    }
    report_ = {};
    done_ = std::move(done);
    scan_ = static_cast<uint16_t>((scan_ + 1) & 0x7FFF);
    log_info("bus scan: %zu probes", steps_.size() - 1);
    next(0);
}

void BusScan::next(uint32_t step) {
    bus_.submit_probe(*this, static_cast<uint32_t>(scan_) << 16 | step);
}

void BusScan::dropped() {
    if (!running())
        return;
    end(bus_.monitor().recovering() ? Result{Status::BusLost, "the I2C bus failed during the scan and is being recovered: scan once it is back"}
                          : Result{Status::Killed, "a kill during the scan ended it: scan again"});
}

IoError BusScan::select(const ScanSegment& s) {
    return s ? bus_.mux().select(bus_.i2c(), s->addr7, s->channel) : bus_.mux().disable_all(bus_.i2c());
}

IoError BusScan::probe(uint32_t job) {
    const uint32_t i = job & 0xFFFF;
    Step& step = steps_[i];
    if (i == 0)
        before_ = bus_.mux().enabled();
    if (step.restore) {
        // Back to what normal operation had selected; nothing selected before: all off.
        return step.error = select(before_);
    }
    step.answer = {};
    if ((step.error = select(step.segment)) != IoError::None)
        return step.error;
    return step.error = probe_thruster(bus_.i2c(), step.mt, step.answer);
}

void BusScan::probed(const BusJobDone& d) {
    const auto job = static_cast<uint32_t>(d.job.value);
    if (!running() || job >> 16 != scan_)
        return;
    if (d.skipped) { // the crash handler has the bus
        end({Status::Hardware, "the bus was taken for the emergency stop"});
        return;
    }
    if (vehicle_.readings().safety().state() != SafetyState::Killed) {
        end({Status::NotKilled, "the vehicle left \"killed\" during the scan (ClearKill?): it ended; Kill and scan again"});
        return;
    }
    const uint32_t i = job & 0xFFFF;
    const Step& step = steps_[i];
    if (step.error == IoError::None && !step.restore)
        add_scan_device(report_, {step.segment, step.mt, step.answer.variant, step.answer.revision, -1});
    else if (step.error != IoError::None && step.error != IoError::Nack) {
        // Not an empty address: the bus failed. The routine transfers will see it too.
        end({Status::Hardware, std::string(step.restore ? "putting the mux back" : "probing " + segment_text(step.segment)) +
                                   " failed: " + std::string(io_error_name(step.error))});
        return;
    }
    if (i + 1 < steps_.size()) {
        next(i + 1);
        return;
    }
    judge_bus_scan(config_.thrusters, report_);
    end({});
}

void BusScan::end(Result r) {
    const std::string what = !r.ok() ? r.message
                             : report_.matches() ? "the bus matches the configuration"
                                                 : "the bus differs from the configuration";
    log_info("bus scan: %s", what.c_str());
    Completion done = std::move(done_);
    done_ = nullptr;
    done(r);
}

void BusScan::stop() {
    if (running())
        end({Status::Busy, "caracarad is stopping"});
}

} // namespace caracara
