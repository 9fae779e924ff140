// An output line on libgpiod's v2 C API (Debian 13, Raspberry Pi OS trixie); the v1 twin is
// libgpiod_output_line.hpp. Outputs use the C API rather than the C++ binding because
// gpiod_line_request_set_value() is one ioctl with its data on the stack, the only way to set
// the kill output from a fatal-signal handler (the C++ set_value allocates).
#pragma once

#include "drivers/platform/gpio_line.hpp"

#include <memory>
#include <string>

struct gpiod_line_request;

namespace caracara {

class Libgpiod2OutputLine final : public GpioLine {
public:
    // mode: Output or OpenDrain. Null with `error` set on failure.
    static std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                             const std::string& consumer, std::string& error);
    ~Libgpiod2OutputLine() override;
    Libgpiod2OutputLine(const Libgpiod2OutputLine&) = delete;
    Libgpiod2OutputLine& operator=(const Libgpiod2OutputLine&) = delete;

    int get() override;
    int set(int value) override;
    bool set_in_signal_handler(int value) noexcept override;

private:
    Libgpiod2OutputLine(gpiod_line_request* request, unsigned int offset) : request_(request), offset_(offset) {}
    gpiod_line_request* request_;
    unsigned int offset_;
};

} // namespace caracara
