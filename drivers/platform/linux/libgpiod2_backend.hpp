// GpioBackend on libgpiod's v2 C++ binding (libgpiod 2.x: Debian 13, Raspberry Pi OS trixie).
// It behaves as the v1 backend (libgpiod_backend.cpp) does: the chip is found as v1's
// OPEN_LOOKUP finds it (libgpiod2_chip_path), lines by name or offset, the same modes,
// active-low applied by the kernel, the consumer name on every request, errors as -errno.
// Inputs are Libgpiod2Line (C++ binding), outputs Libgpiod2OutputLine (C API, signal-safe set).
#pragma once

#include "drivers/platform/gpio_backend.hpp"

#include <memory>
#include <string>

namespace caracara {

class Libgpiod2Backend final : public GpioBackend {
public:
    explicit Libgpiod2Backend(std::string consumer) : consumer_(std::move(consumer)) {}
    std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                      std::string& error) override;

private:
    std::string consumer_;
};

} // namespace caracara
