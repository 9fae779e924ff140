// The Confirm handshake that ends a Turn (Pi-Teensy SPI protocol, Confirm command; the byte
// meanings are in docs/teensy-protocol.md). Pure: time is passed in.
#pragma once

#include "drivers/protocol/teensy_codec.hpp"

#include <cstdint>

namespace caracara::teensy {

// After Turn / Turn to was accepted: poll Confirm(0) until the answer is 0xFF, then send
// Confirm(1) once as acknowledgement. Non-blocking: next() says which frame to send and when;
// the owner sends it (TeensyLink::execute) and reports the outcome with on_result().
class ConfirmHandshake {
public:
    enum class State : uint8_t { Idle, Polling, Acknowledging, Done, Failed };
    enum class Action : uint8_t {
        Idle,   // start() not called
        Send,   // send `frame` now, then call on_result()
        Wait,   // nothing to send before `at_ns`
        Done,   // task finished and acknowledged
        Failed, // see `error`
    };
    struct Step {
        Action action = Action::Idle;
        Frame frame{};
        uint64_t at_ns = 0;
        TeensyError error = TeensyError::None;
    };

    explicit ConfirmHandshake(ConfirmHandshakeConfig config = {}) : config_(config) {}

    void start(uint64_t now_ns);
    Step next(uint64_t now_ns);
    // The outcome of the frame last returned with Action::Send: the Confirm answer byte, or
    // the link error. Ignored when no Send is outstanding.
    void on_result(const TeensyResult<uint8_t>& result, uint64_t now_ns);

    State state() const { return state_; }
    TeensyError error() const { return error_; }
    TeensyError last_link_error() const { return last_link_error_; }
    unsigned polls() const { return polls_; }

private:
    ConfirmHandshakeConfig config_;
    State state_ = State::Idle;
    TeensyError error_ = TeensyError::None;
    TeensyError last_link_error_ = TeensyError::None;
    uint64_t deadline_ns_ = 0;
    uint64_t next_send_ns_ = 0;
    unsigned polls_ = 0;
    unsigned acks_sent_ = 0;
    bool awaiting_ = false;
};

} // namespace caracara::teensy
