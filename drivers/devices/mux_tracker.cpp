#include "drivers/devices/mux_tracker.hpp"

#include "drivers/protocol/pca9544a.hpp"

namespace caracara {

namespace {

std::size_t mux_index(uint16_t addr7) { return static_cast<std::size_t>(addr7 - kMuxAddrMin); }

} // namespace

void MuxTracker::add_mux(uint16_t addr7) {
    if (!is_valid_mux_addr7(addr7))
        return;
    const std::size_t i = mux_index(addr7);
    if (!known_[i]) {
        known_[i] = true;
        state_[i] = kUnknown;
    }
}

IoError MuxTracker::write_control(I2cDev& bus, std::size_t index, uint8_t value) {
    const std::array<uint8_t, 1> byte{value};
    ++control_writes_;
    const IoError e = bus.write(static_cast<uint16_t>(kMuxAddrMin + index), byte);
    if (e != IoError::None) {
        ++control_failures_;
        state_[index] = kUnknown;
    }
    return e;
}

IoError MuxTracker::select(I2cDev& bus, uint16_t addr7, uint8_t channel) {
    if (!is_valid_mux_addr7(addr7) || channel >= kMuxChannels)
        return IoError::Other;
    add_mux(addr7);
    const std::size_t target = mux_index(addr7);
    // Another mux with a channel enabled (or in an unknown state, e.g. left over from a
    // previous run) could put a same-address thruster on the bus next to ours.
    if (const IoError e = disable_others(bus, target); e != IoError::None)
        return e;
    if (state_[target] == static_cast<int8_t>(channel))
        return IoError::None;
    const IoError e = write_control(bus, target, mux_control_byte(channel));
    if (e != IoError::None)
        return e;
    state_[target] = static_cast<int8_t>(channel);
    return IoError::None;
}

IoError MuxTracker::disable_others(I2cDev& bus, std::size_t keep) {
    for (std::size_t i = 0; i < known_.size(); ++i) {
        if (i == keep || !known_[i] || state_[i] == kDisabled)
            continue;
        const IoError e = write_control(bus, i, kMuxDisableAll);
        if (e != IoError::None)
            return e;
        state_[i] = kDisabled;
    }
    return IoError::None;
}

IoError MuxTracker::disable_all(I2cDev& bus) { return disable_others(bus, known_.size()); }

std::optional<MuxRoute> MuxTracker::enabled() const {
    for (std::size_t i = 0; i < known_.size(); ++i)
        if (known_[i] && state_[i] >= 0)
            return MuxRoute{static_cast<uint16_t>(kMuxAddrMin + i), static_cast<uint8_t>(state_[i])};
    return std::nullopt;
}

void MuxTracker::invalidate() { state_.fill(kUnknown); }

void MuxTracker::invalidate(uint16_t addr7) {
    if (is_valid_mux_addr7(addr7))
        state_[mux_index(addr7)] = kUnknown;
}

bool MuxTracker::known(uint16_t addr7) const { return is_valid_mux_addr7(addr7) && known_[mux_index(addr7)]; }

std::optional<uint8_t> MuxTracker::selected_channel(uint16_t addr7) const {
    if (!known(addr7) || state_[mux_index(addr7)] < 0)
        return std::nullopt;
    return static_cast<uint8_t>(state_[mux_index(addr7)]);
}

bool MuxTracker::known_disabled(uint16_t addr7) const {
    return known(addr7) && state_[mux_index(addr7)] == kDisabled;
}

} // namespace caracara
