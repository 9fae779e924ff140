#include "tools/bridge/send_queue.hpp"

namespace caracara::bridge {

bool SendQueue::push(Frame f) {
    if (!f.droppable) {
        if (reply_bytes_ + f.bytes->size() > max_reply_bytes_)
            return false;
        reply_bytes_ += f.bytes->size();
    } else if (messages_ >= max_messages_) {
        for (auto it = frames_.begin() + (writing_ ? 1 : 0); it != frames_.end(); ++it)
            if (it->droppable) {
                frames_.erase(it);
                --messages_;
                ++dropped_;
                break;
            }
    }
    messages_ += f.droppable ? 1 : 0;
    frames_.push_back(std::move(f));
    return true;
}

const SendQueue::Frame& SendQueue::start_front() {
    writing_ = true;
    return frames_.front();
}

void SendQueue::forget(const Frame& f) {
    if (f.droppable)
        --messages_;
    else
        reply_bytes_ -= f.bytes->size();
}

void SendQueue::pop_front() {
    writing_ = false;
    forget(frames_.front());
    frames_.pop_front();
}

void SendQueue::clear_waiting() {
    while (frames_.size() > (writing_ ? 1u : 0u)) {
        forget(frames_.back());
        frames_.pop_back();
    }
}

} // namespace caracara::bridge
