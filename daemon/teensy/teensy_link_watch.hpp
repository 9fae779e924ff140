// Whether the Teensy's link is lost, and why: the SPI device went away, a fitted Teensy was
// absent at start, or no valid frame came back for [spi] silence_ms of asking (busy for ever, no
// answer, garbage, a frame held on the wire). The silence counts only while the Teensy is asked:
// a poll held back behind a hung I2C bus (the Teensy's slot comes after the cycle's transfers) is
// no silence of the Teensy's. Owns the silence timer; TeensyConnection tells it what happens on
// the link and carries out a loss (`on_silent`).
#pragma once

#include "core/config.hpp"
#include "core/enum_names.hpp"
#include "drivers/platform/event_loop.hpp"

#include <cstdint>
#include <functional>
#include <string>

namespace caracara {

enum class TeensyLoss : uint8_t { None, Gone, Absent, Silent };
template <>
struct EnumNames<TeensyLoss> {
    static constexpr std::array<EnumName<TeensyLoss>, 4> table{{
        {TeensyLoss::None, "none"},
        {TeensyLoss::Gone, "gone"},
        {TeensyLoss::Absent, "absent"},
        {TeensyLoss::Silent, "silent"},
    }};
};

class TeensyLinkWatch {
public:
    // `relied_on`: whether a silence now counts (the node open, and the Teensy fitted or heard
    // once); `on_silent(ms)`: asked for `ms` and no valid frame.
    TeensyLinkWatch(const SpiSettings& settings, std::function<void()> collect, std::function<bool()> open,
                    std::function<void(uint64_t)> on_silent)
        : fitted_(settings.fitted), silence_ns_(ms_to_ns(settings.silence_ms)), collect_(std::move(collect)),
          open_(std::move(open)), on_silent_(std::move(on_silent)) {}

    std::string start(sd_event* event);
    void stop() { timer_.reset(); }

    bool fitted() const { return fitted_; }
    TeensyLoss loss() const { return loss_; }
    // Lost for `why`; false when it already was (the kill is told once).
    bool lose(TeensyLoss why);
    void gone() { loss_ = TeensyLoss::None; } // whatever it was before, the device is gone now
    // A frame handed to the worker: the silence counts from the first since the last valid one.
    void asked();
    void reopened() { asked_ns_ = 0; } // the silence counts from its first frame
    // A valid frame came back (`now`): true when the link was lost and is back.
    bool heard(uint64_t now);

private:
    static int on_timer(sd_event_source*, uint64_t usec, void* userdata);
    void arm(uint64_t at_ns); // monotonic ns

    TeensyLoss loss_ = TeensyLoss::None;
    bool fitted_;           // [spi] fitted
    bool answered_ = false; // a valid frame came once (a Teensy not fitted is then relied on)
    uint64_t silence_ns_;
    uint64_t asked_ns_ = 0; // when the first frame since the last valid one was handed over (0: none)
    std::function<void()> collect_;
    std::function<bool()> open_;
    std::function<void(uint64_t)> on_silent_;
    SourcePtr timer_;
};

} // namespace caracara
