#include "daemon/vehicle_daemon.hpp"

#include "daemon/loop/log.hpp"
#include "daemon/loop/thread_schedule.hpp"
#include "drivers/platform/io_error.hpp"

namespace caracara {

VehicleDaemon::VehicleDaemon(sd_event* event, DeviceIo& io, DeviceIo& bus_io, DeviceIo& spi_io, GpioBackend& gpio,
                             DaemonConfig config)
    : event_(event),
      config_(std::move(config)),
      bus_(bus_io, config_, events_),
      // The failsafes, made below, are where the lines, the Teensy link, the pilot watch and the
      // bus loss push their conditions; nothing pushes before start().
      lines_(event, gpio, config_.gpio, failsafes_),
      teensy_(event, spi_io, config_.spi, vehicle_, failsafes_, events_),
      vehicle_(config_, bus_, lines_, teensy_, events_, failsafes_),
      packets_(vehicle_, teensy_),
      loop_(event, config_.control, vehicle_, bus_, teensy_, lines_, events_),
      recovery_(event, config_, io, gpio, bus_, loop_, failsafes_, events_),
      status_(event, vehicle_, bus_, loop_),
      failsafes_(event, config_.failsafe, bus_.size(), [this](std::size_t i) { return reading(i); }, vehicle_,
                 events_),
      motor_test_(config_, vehicle_, events_),
      directions_(config_, vehicle_, teensy_, failsafes_),
      preflight_(config_, bus_, teensy_, lines_),
      bus_scan_(config_, vehicle_, bus_) {
    vehicle_.set_demand_listener(&loop_);
    bus_.monitor().set_listener(&recovery_);
    events_.attach_status(&status_);
    status_.set_failsafe_summary([this] { return failsafes_.summary(); });
}

std::optional<FailsafeReading> VehicleDaemon::reading(std::size_t i) const {
    const auto& st = bus_.thruster(i).last_status();
    if (!st || !bus_.thruster(i).online())
        return std::nullopt;
    return FailsafeReading{st->faults.bits, st->temperature_c};
}

std::string VehicleDaemon::start() {
    if (int r = bus_.open(); r < 0)
        return "cannot open I2C bus " + config_.i2c.device + ": " + errno_name(-r);
    // Each thread inherits the schedule of this one when it is made (ThreadSchedule).
    const RealtimeSettings& rt = config_.realtime;
    ThreadSchedule schedule(rt);
    schedule.realtime(rt.bus_priority);
    if (std::string e = bus_.start(event_, kWorkPriority, [this](const BusJob& j) { loop_.bus_done(j); }); !e.empty())
        return e;
    // Zero before anything else: a previous instance may have died with orders standing.
    bus_.zero_all();
    bus_.worker().wait_idle();
    if (std::string e = lines_.open(vehicle_.readings().kill_output_asserted(), &vehicle_); !e.empty())
        return e;
    if (int r = teensy_.open(); r < 0 && !config_.spi.fitted)
        log_warning("Teensy SPI %s unavailable (%s); continuing without it", config_.spi.device.c_str(),
                    errno_name(-r).c_str());
    teensy_.stop_motion(); // the wheels too may have been left running by an earlier instance
    schedule.realtime(rt.teensy_priority);
    if (std::string e = teensy_.start(kWorkPriority); !e.empty())
        return e;
    if (std::string e = vehicle_.start(event_); !e.empty())
        return e;
    bus_.health().set_failsafes(&failsafes_); // a thruster that stopped answering: thruster-unreachable
    // The dive writer's file writes can wait: never ahead of the loop or the wire.
    schedule.normal();
    if (config_.recorder.enabled) {
        dive_writer_ = std::make_unique<DiveWriter>(config_.recorder.directory,
                                                    uint64_t(config_.recorder.max_total_mb) << 20);
        dive_writer_->start();
        recorder_ = std::make_unique<DiveRecorder>(config_, vehicle_, bus_, teensy_, events_, *dive_writer_,
                                                   motor_test_, directions_);
        events_.attach_recorder(recorder_.get());
        recorder_->start();
    }
    // The loop: the kill switch's edge, the kill output, every tick.
    schedule.realtime(rt.loop_priority);
    if (rt.enabled && !schedule.refused())
        log_notice("realtime: policy %s, loop at %u, bus worker at %u, Teensy worker at %u, dive writer at the normal policy",
                   std::string(name_of(rt.policy)).c_str(), rt.loop_priority, rt.bus_priority, rt.teensy_priority);
    if (std::string e = loop_.start(); !e.empty())
        return e;
    if (std::string e = failsafes_.start(); !e.empty())
        return e;
    if (std::string e = motor_test_.start(event_); !e.empty())
        return e;
    if (std::string e = directions_.start(event_); !e.empty())
        return e;
    if (std::string e = preflight_.start(event_); !e.empty())
        return e;
    started_ = true;
    return {};
}

void VehicleDaemon::attach_emergency_stop(EmergencyStop& stop) {
    bus_.worker().set_gate(&stop.bus_gate());
    lines_.set_kill_output_watcher(&stop);
    recovery_.set_node_holder(&stop);
}

void VehicleDaemon::shutdown() {
    if (!started_)
        return;
    started_ = false;
    bus_.health().set_failsafes(nullptr);
    loop_.stop();
    failsafes_.stop();
    motor_test_.stop();
    directions_.stop();
    preflight_.stop();
    bus_scan_.stop();
    if (recorder_) {
        recorder_->stop(); // the dive ends here, before the zeros of the way out
        events_.attach_recorder(nullptr);
        dive_writer_->drain();
    }
    vehicle_.stop();
    recovery_.stop();
    lines_.close();
    bus_.zero_all();
    bus_.worker().wait_idle();
    bus_.stop();
    teensy_.stop_motion();
    teensy_.close();
    bus_.close();
}

} // namespace caracara
