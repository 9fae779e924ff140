// The kill switch's input line, in the manner of logind's button: its edges wake the loop above
// D-Bus and the bus work. A line that cannot be read is dropped (its source with it, no busy
// loop) and reported lost; SafetyLines counts it as set and asks for it again.
#pragma once

#include "core/config.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/platform/gpio_backend.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace caracara {

class KillSwitch {
public:
    using Edge = std::function<void()>;
    using Lost = std::function<void(const std::string& why)>;
    // `edge`: the level may have changed (read() tells it); `lost`: the line was dropped.
    KillSwitch(sd_event* event, GpioBackend& gpio, const std::optional<GpioLineSettings>& settings, Edge edge, Lost lost)
        : event_(event), gpio_(gpio), settings_(settings), edge_(std::move(edge)), lost_(std::move(lost)) {}

    // Requests the line and watches its edges; "" or why not.
    std::string open();
    void close() { source_.reset(); }
    bool is_open() const { return line_ != nullptr; }
    // Configured, but cannot be read now (it counts as set meanwhile).
    bool unreadable() const { return settings_ && !line_; }
    // Set (a kill) or not; nullopt when it cannot be read (then dropped and reported lost).
    std::optional<bool> read();
    // The same reading without dropping a line that fails (the preflight only looks).
    std::optional<bool> level() const;
    // The event fd (for the loop's "is anything waiting" check), or -1.
    int fd() const { return line_ ? line_->event_fd() : -1; }

private:
    static int on_edge(sd_event_source*, int fd, uint32_t revents, void* userdata);
    void drop(const std::string& why);

    sd_event* event_;
    GpioBackend& gpio_;
    const std::optional<GpioLineSettings>& settings_;
    Edge edge_;
    Lost lost_;
    std::unique_ptr<GpioLine> line_;
    SourcePtr source_;
};

} // namespace caracara
