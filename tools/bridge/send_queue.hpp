// What waits to be written to one WebSocket client: its messages (droppable, at most a bound
// of them) and its protocol replies (never dropped). When the bound is reached the oldest
// waiting message goes, never the frame being written: a client that does not keep up sees
// fewer, newer messages, and nobody waits for it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

namespace caracara::bridge {

class SendQueue {
public:
    struct Frame {
        bool text = false;
        bool droppable = false;  // a messageData frame; replies are not
        std::shared_ptr<const std::string> bytes;
    };

    explicit SendQueue(std::size_t max_messages) : max_messages_(max_messages) {}

    void push(Frame f);
    bool empty() const { return frames_.empty(); }
    std::size_t size() const { return frames_.size(); }
    // The next frame to write; from then on it is in flight until pop_front().
    const Frame& start_front();
    bool writing() const { return writing_; }
    void pop_front();
    uint64_t dropped() const { return dropped_; }

private:
    std::size_t max_messages_;
    std::deque<Frame> frames_;
    std::size_t messages_ = 0;
    bool writing_ = false;
    uint64_t dropped_ = 0;
};

} // namespace caracara::bridge
