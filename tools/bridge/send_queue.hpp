// What waits to be written to one WebSocket client: its messages (droppable, at most a bound
// of them) and its protocol replies and status messages (never dropped, but counted: at most
// max_reply_bytes of them wait). When the message bound is reached the oldest waiting message
// goes, never the frame being written: a client that does not keep up sees fewer, newer
// messages, and nobody waits for it. A client whose replies pass their bound is one that sends
// and never reads: push() says so, and the session closes it.
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

    SendQueue(std::size_t max_messages, std::size_t max_reply_bytes)
        : max_messages_(max_messages), max_reply_bytes_(max_reply_bytes) {}

    // False when a reply would take the replies past max_reply_bytes (it is not queued).
    bool push(Frame f);
    bool empty() const { return frames_.empty(); }
    std::size_t size() const { return frames_.size(); }
    // The bytes of the replies waiting (the one being written included).
    std::size_t reply_bytes() const { return reply_bytes_; }
    // The next frame to write; from then on it is in flight until pop_front().
    const Frame& start_front();
    bool writing() const { return writing_; }
    void pop_front();
    // Everything but the frame in flight goes (the client is being closed).
    void clear_waiting();
    uint64_t dropped() const { return dropped_; }

private:
    void forget(const Frame& f);

    std::size_t max_messages_;
    std::size_t max_reply_bytes_;
    std::deque<Frame> frames_;
    std::size_t messages_ = 0;
    std::size_t reply_bytes_ = 0;
    bool writing_ = false;
    uint64_t dropped_ = 0;
};

} // namespace caracara::bridge
