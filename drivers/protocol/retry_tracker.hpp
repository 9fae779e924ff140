// The busy/link-error retry decision of the Teensy frame engine (docs/teensy-protocol.md):
// pure, so it is tested without SPI.
#pragma once

#include "drivers/protocol/teensy_codec.hpp"

#include <cstdint>

namespace caracara::teensy {

// What the frame engine does after each reply, kept here so it can be tested without SPI.
enum class RetryAction : uint8_t {
    Done,             // Ok: decode the answer
    ResendAfterDelay, // wait busy_delay_us, then send the very same frame again
    Fail,             // give up with `error`
};

struct RetryDecision {
    RetryAction action = RetryAction::Fail;
    TeensyError error = TeensyError::None;
};

// One instance per execute(): counts the busy and link-error resends of one frame.
class RetryTracker {
public:
    RetryTracker(const RetryPolicy& policy, const CommandInfo& command)
        : policy_(policy), command_(command) {}
    RetryDecision on_reply(FrameStatus status);
    unsigned busy_retries() const { return busy_retries_; }
    unsigned link_retries() const { return link_retries_; }

private:
    RetryPolicy policy_;
    CommandInfo command_;
    unsigned busy_retries_ = 0;
    unsigned link_retries_ = 0;
};

} // namespace caracara::teensy
