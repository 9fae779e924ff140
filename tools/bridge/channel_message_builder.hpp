// The Foxglove channels' messages (tools/foxglove/channels.hpp) made from caracarad's properties
// as Telemetry mirrors them: one JSON message a channel, built when the channel changed. Beside
// the properties, /vehicle/state carries two things the bridge observes itself: since when a
// surface failsafe's ascent has run, and the controller in words.
#pragma once

#include "tools/client/object_mirror.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace caracara::bridge {

class ChannelMessageBuilder {
public:
    explicit ChannelMessageBuilder(const client::ObjectMirror& mirror) : mirror_(mirror) {}

    // Follows the root's properties at `now` (ns since the epoch): when a surface failsafe's
    // ascent began (surfacing_ms in the state).
    void follow_surfacing(const client::Props& root, uint64_t now);
    // The controller is now `unique_name` (a bus name), not yet described in words.
    void controller_changed(const std::string& unique_name) { controller_ = {unique_name, ""}; }
    // The current controller in words (controller_name in the state).
    void describe_controller(std::string words) { controller_.words = std::move(words); }

    // The JSON message of the channel at that position in foxglove::channels(), at `now`; none for
    // the events channel, whose messages are made as things happen.
    std::optional<std::string> build(std::size_t channel, uint64_t now) const;

private:
    std::string vehicle_state(uint64_t now) const;
    std::string motors() const;
    std::string thruster(unsigned index) const;
    std::string teensy(bool attitude_only, uint64_t now) const;
    std::string i2c_bus() const;

    const client::ObjectMirror& mirror_;
    uint64_t surfacing_since_ = 0; // CLOCK_REALTIME ns; 0 not surfacing
    struct ControllerName {
        std::string unique_name, words;
    } controller_;
};

} // namespace caracara::bridge
