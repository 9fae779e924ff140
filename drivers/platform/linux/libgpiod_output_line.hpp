// An output line on libgpiod's v1 C API (Debian 12). Outputs use the C API rather than the C++
// binding because gpiod_line_set_value() is one ioctl with its data on the stack: the only way
// to write the kill output from a fatal-signal handler (the C++ set_value allocates).
#pragma once

#include "drivers/platform/gpio_line.hpp"

#include <memory>
#include <string>

struct gpiod_chip;
struct gpiod_line;

namespace caracara {

class LibgpiodOutputLine final : public GpioLine {
public:
    // mode: Output or OpenDrain. Null with `error` set on failure.
    static std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                             const std::string& consumer, std::string& error);
    ~LibgpiodOutputLine() override;
    LibgpiodOutputLine(const LibgpiodOutputLine&) = delete;
    LibgpiodOutputLine& operator=(const LibgpiodOutputLine&) = delete;

    int get() override;
    int set(int value) override;
    bool set_in_signal_handler(int value) noexcept override;

private:
    LibgpiodOutputLine(gpiod_chip* chip, gpiod_line* line) : chip_(chip), line_(line) {}
    gpiod_chip* chip_;
    gpiod_line* line_;
};

} // namespace caracara
