// An input line, with or without edge events, on libgpiod's v2 C++ binding (libgpiod 2.x: Debian
// 13, Raspberry Pi OS trixie); made by Libgpiod2Backend (outputs: Libgpiod2OutputLine). Values
// are logical: the kernel applies active-low.
#pragma once

#include "drivers/platform/gpio_line.hpp"

#include <gpiod.hpp>

namespace caracara {

class Libgpiod2Line final : public GpioLine {
public:
    Libgpiod2Line(gpiod::line_request request, gpiod::line::offset offset, bool edges);
    ~Libgpiod2Line() override;
    Libgpiod2Line(const Libgpiod2Line&) = delete;
    Libgpiod2Line& operator=(const Libgpiod2Line&) = delete;

    int get() override;
    int set(int value) override;
    int event_fd() const override;
    int drain_events() override;

    // The errno behind an exception of the binding: it throws std::system_error for most
    // failures but maps EINVAL, E2BIG, ENOMEM and EDOM to standard exceptions of their own.
    static int errno_of(const std::exception& e);

private:
    gpiod::line_request request_;
    gpiod::line::offset offset_;
    bool edges_;
    gpiod::edge_event_buffer events_;
};

} // namespace caracara
