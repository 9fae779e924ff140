#include "daemon/vehicle_events.hpp"

#include "daemon/service_status.hpp"

namespace caracara {

void VehicleEvents::changed(uint32_t changes) {
    if ((changes & (kChangeState | kChangeBus | kChangeProfile | kChangeFaults | kChangeFailsafes)) && status_)
        status_->publish();
    if (changes && recorder_)
        recorder_->vehicle_changed(changes);
    if (changes && observer_)
        observer_->vehicle_changed(changes);
}

} // namespace caracara
