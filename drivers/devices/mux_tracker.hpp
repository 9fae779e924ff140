// PCA9544A multiplexer state on one I2C bus (see drivers/protocol/pca9544a.hpp for the control byte).
#pragma once

#include "core/thruster_config.hpp"
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/platform/io_error.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace caracara {

// Remembers what each PCA9544A on one bus has selected, so a thruster behind a mux costs
// a control write only when the channel changes. Same-address thrusters may sit behind
// different muxes, so at most one mux has a channel enabled at any time: selecting on one
// first disables every other known mux whose state is not known to be "all off".
class MuxTracker {
public:
    MuxTracker() { invalidate(); }

    // Makes `addr7` known to the tracker (state unknown), so selects on other muxes disable it.
    void add_mux(uint16_t addr7);
    // Ensures `channel` is the only enabled channel of the muxes on this bus. Each control
    // write is its own I2C_RDWR. On failure the state of the mux that failed becomes unknown.
    // IoError::Other without bus traffic for an address outside 0x70..0x77 or channel > 3.
    IoError select(I2cDev& bus, uint16_t addr7, uint8_t channel);
    // Every known mux with no channel enabled (a bus scan's look at the trunk alone).
    IoError disable_all(I2cDev& bus);
    // The one mux known to have a channel enabled, and that channel.
    std::optional<MuxRoute> enabled() const;
    // Forget all state (after any bus error, recovery or reopen): the next select writes again.
    void invalidate();
    void invalidate(uint16_t addr7);

    // Inspection, for telemetry and tests.
    bool known(uint16_t addr7) const;
    std::optional<uint8_t> selected_channel(uint16_t addr7) const;  // known to be enabled
    bool known_disabled(uint16_t addr7) const;
    uint64_t control_writes() const { return control_writes_; }
    uint64_t control_failures() const { return control_failures_; }

private:
    static constexpr int8_t kUnknown = -1;
    static constexpr int8_t kDisabled = -2;
    IoError write_control(I2cDev& bus, std::size_t index, uint8_t value);
    // Disables every known mux but the one at index `keep` (none kept when out of range).
    IoError disable_others(I2cDev& bus, std::size_t keep);

    std::array<bool, 8> known_{};
    std::array<int8_t, 8> state_{};  // channel 0..3, kUnknown or kDisabled
    uint64_t control_writes_ = 0;
    uint64_t control_failures_ = 0;
};

} // namespace caracara
