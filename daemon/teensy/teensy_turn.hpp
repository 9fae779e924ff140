// A Turn (relative) or Turn to (absolute) on the Teensy and its Confirm handshake
// (TeensyLink::advance), which runs on a timer of its own so the loop never waits for a turn
// to finish; each step's frame is carried by the connection's worker. `done` runs when the
// Teensy confirms completion, on failure, or when the turn is cancelled (kill, shutdown).
#pragma once

#include "core/status.hpp"
#include "daemon/loop/completion.hpp"
#include "daemon/teensy/teensy_connection.hpp"
#include "daemon/interfaces/command_gate.hpp"
#include "drivers/platform/event_loop.hpp"
#include "drivers/protocol/teensy_codec.hpp"

#include <cstdint>
#include <string_view>

namespace caracara {

class TeensyTurn {
public:
    TeensyTurn(sd_event* event, TeensyConnection& connection, CommandGate& gate)
        : event_(event), connection_(connection), gate_(gate) {}

    // A motor command from `client`, under the command timeout.
    Result start(double radians, bool absolute, std::string_view client, Completion done);
    bool running() const { return static_cast<bool>(done_); }
    // Ends a running turn with `r`.
    void cancel(const Result& r) {
        if (done_)
            finish(r);
    }

private:
    static int on_step(sd_event_source*, uint64_t usec, void* userdata);
    void step();
    void finish(const Result& r);

    sd_event* event_;
    TeensyConnection& connection_;
    CommandGate& gate_;
    teensy::ConfirmHandshake handshake_; // the worker's while a step is out
    teensy::ConfirmHandshake::Step step_;
    uint64_t id_ = 0; // a step's result for a turn that ended meanwhile is dropped
    Completion done_;
    SourcePtr source_;
};

} // namespace caracara
