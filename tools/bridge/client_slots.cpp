#include "tools/bridge/client_slots.hpp"

namespace caracara::bridge {

std::shared_ptr<void> ClientSlots::claim() {
    if (*taken_ >= max_)
        return nullptr;
    ++*taken_;
    // The handle counts back down even after the ClientSlots is gone (the counter is shared).
    return std::shared_ptr<void>(taken_.get(), [taken = taken_](void*) { --*taken; });
}

} // namespace caracara::bridge
