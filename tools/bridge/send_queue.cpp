#include "tools/bridge/send_queue.hpp"

namespace caracara::bridge {

void SendQueue::push(Frame f) {
    if (f.droppable && messages_ >= max_messages_) {
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
}

const SendQueue::Frame& SendQueue::start_front() {
    writing_ = true;
    return frames_.front();
}

void SendQueue::pop_front() {
    writing_ = false;
    if (frames_.front().droppable)
        --messages_;
    frames_.pop_front();
}

} // namespace caracara::bridge
