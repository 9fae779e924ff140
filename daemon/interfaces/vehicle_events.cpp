#include "daemon/interfaces/vehicle_events.hpp"

namespace caracara {

void VehicleEvents::changed(uint32_t changes) {
    if (changes && status_)
        status_->vehicle_changed(changes);
    if (changes && recorder_)
        recorder_->vehicle_changed(changes);
    if (changes && observer_)
        observer_->vehicle_changed(changes);
}

} // namespace caracara
