#include "drivers/protocol/retry_tracker.hpp"

namespace caracara::teensy {

RetryDecision RetryTracker::on_reply(FrameStatus status) {
    switch (status) {
    case FrameStatus::Ok:
        return {RetryAction::Done, TeensyError::None};
    case FrameStatus::Busy:
        if (busy_retries_ < policy_.max_busy_retries) {
            ++busy_retries_;
            return {RetryAction::ResendAfterDelay, TeensyError::Busy};
        }
        return {RetryAction::Fail, TeensyError::BusyExhausted};
    case FrameStatus::LinkError:
        if (policy_.retry_link_error_once && command_.idempotent && link_retries_ == 0) {
            ++link_retries_;
            return {RetryAction::ResendAfterDelay, TeensyError::LinkError};
        }
        return {RetryAction::Fail, TeensyError::LinkError};
    }
    return {RetryAction::Fail, TeensyError::LinkError};
}

} // namespace caracara::teensy
