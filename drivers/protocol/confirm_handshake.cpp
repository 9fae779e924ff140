#include "drivers/protocol/confirm_handshake.hpp"

namespace caracara::teensy {

void ConfirmHandshake::start(uint64_t now_ns) {
    state_ = State::Polling;
    error_ = TeensyError::None;
    last_link_error_ = TeensyError::None;
    // Saturate: a huge timeout means "practically never", not a wrapped deadline in the past.
    deadline_ns_ = config_.timeout_ns > UINT64_MAX - now_ns ? UINT64_MAX : now_ns + config_.timeout_ns;
    next_send_ns_ = now_ns;
    polls_ = 0;
    acks_sent_ = 0;
    awaiting_ = false;
}

ConfirmHandshake::Step ConfirmHandshake::next(uint64_t now_ns) {
    Step s;
    switch (state_) {
    case State::Idle:
        s.action = Action::Idle;
        return s;
    case State::Done:
        s.action = Action::Done;
        return s;
    case State::Failed:
        s.action = Action::Failed;
        s.error = error_;
        return s;
    case State::Polling:
        if (now_ns >= deadline_ns_) {
            state_ = State::Failed;
            error_ = TeensyError::ConfirmTimeout;
            awaiting_ = false;
            s.action = Action::Failed;
            s.error = error_;
            return s;
        }
        if (now_ns < next_send_ns_) {
            s.action = Action::Wait;
            s.at_ns = std::min(next_send_ns_, deadline_ns_);
            return s;
        }
        s.action = Action::Send;
        s.frame = encode_confirm(kConfirmPoll).value;
        s.at_ns = now_ns;
        awaiting_ = true;
        return s;
    case State::Acknowledging:
        // No deadline here: the task has finished, and the attempts bound this phase.
        if (now_ns < next_send_ns_) {
            s.action = Action::Wait;
            s.at_ns = next_send_ns_;
            return s;
        }
        s.action = Action::Send;
        s.frame = encode_confirm(kConfirmAck).value;
        s.at_ns = now_ns;
        awaiting_ = true;
        return s;
    }
    return s;
}

void ConfirmHandshake::on_result(const TeensyResult<uint8_t>& result, uint64_t now_ns) {
    if (!awaiting_)
        return;
    awaiting_ = false;
    if (!result.ok())
        last_link_error_ = result.error;
    const uint64_t later = config_.poll_interval_ns > UINT64_MAX - now_ns ? UINT64_MAX
                                                                          : now_ns + config_.poll_interval_ns;
    if (state_ == State::Polling) {
        ++polls_;
        // Accepted even past the deadline: the answer is in, the task is finished.
        if (result.ok() && result.value == kConfirmFinished) {
            state_ = State::Acknowledging;
            next_send_ns_ = now_ns;
        } else {
            // 0 (still running), any other value (reserved) or a link failure: poll again.
            next_send_ns_ = later;
        }
    } else if (state_ == State::Acknowledging) {
        ++acks_sent_;
        if (result.ok()) {
            state_ = State::Done;
        } else if (acks_sent_ >= std::max(config_.ack_attempts, 1u)) {
            state_ = State::Failed;
            error_ = TeensyError::ConfirmAckFailed;
        } else {
            next_send_ns_ = later;
        }
    }
}

} // namespace caracara::teensy
