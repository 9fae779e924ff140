#include "daemon/recovery/bus_recovery_steps.hpp"

#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/platform/line_spec.hpp"

#include <cerrno>

namespace caracara {

void BusRecoverySteps::close_adapter() {
    bus_.close();
    bus_.mux().invalidate();
}

BusClearResult BusRecoverySteps::clear() {
    const RecoverySettings& rc = config_.recovery;
    close_adapter(); // before unbinding: the driver cannot go while the node is open
    const bool rebind = !rc.driver_id.empty();
    if (rebind)
        release_node_holder(); // nor while anyone else has it open (found on a real kernel)
    if (rebind) {
        if (int r = sysfs_write(io_, rc.unbind_path, rc.driver_id); r < 0 && r != -ENODEV)
            log_warning("unbinding %s via %s: %s", rc.driver_id.c_str(), rc.unbind_path.c_str(), errno_name(-r).c_str());
    }
    BusClearResult bc = i2c_bus_clear(gpio_, line_spec(*config_.gpio.scl), line_spec(*config_.gpio.sda));
    if (rebind) {
        // Even after a failed clear: the node must come back for the next attempt.
        if (int r = sysfs_write(io_, rc.bind_path, rc.driver_id); r < 0 && r != -EBUSY)
            log_warning("binding %s via %s: %s", rc.driver_id.c_str(), rc.bind_path.c_str(), errno_name(-r).c_str());
    }
    if (bc.ok())
        log_info("bus clear: SDA released after %u clock pulses, STOP sent", bc.pulses);
    return bc;
}

int BusRecoverySteps::open_node() {
    const int r = bus_.open();
    if (r == 0)
        reopen_node_holder();
    return r;
}

void BusRecoverySteps::reopen_adapter() {
    close_adapter();
    // Quietly: one line when it went, one when it is back (ThrusterBus::note). The emergency
    // stop's connection to the node is renewed with it (a restarted simulator).
    release_node_holder();
    open_node();
}

void BusRecoverySteps::release_node_holder() {
    if (node_holder_)
        node_holder_->release();
}

void BusRecoverySteps::reopen_node_holder() {
    if (!node_holder_)
        return;
    if (std::string why = node_holder_->reopen(); !why.empty())
        log_warning("emergency stop not re-armed: %s", why.c_str());
}

} // namespace caracara
