// caracara-bridge's per-client send queue (tools/bridge/send_queue.hpp): a client that does not
// keep up gets the newest messages, its protocol replies all (up to their byte bound, past which
// the client is closed), and the frame being written is never taken from under the write.
#include "tests/catch.hpp"
#include "tools/bridge/send_queue.hpp"

#include <string>
#include <vector>

using caracara::bridge::SendQueue;

namespace {

SendQueue::Frame message(int n) { return {false, true, std::make_shared<const std::string>(std::to_string(n))}; }
SendQueue::Frame reply(const char* s) { return {true, false, std::make_shared<const std::string>(s)}; }

std::vector<std::string> drain(SendQueue& q) {
    std::vector<std::string> out;
    while (!q.empty()) {
        out.push_back(*q.start_front().bytes);
        q.pop_front();
    }
    return out;
}

} // namespace

TEST_CASE("a slow client keeps the newest messages, in order, within the bound", "[bridge]") {
    SendQueue q(4, 1024);
    for (int i = 0; i < 10; ++i)
        q.push(message(i));
    CHECK(q.size() == 4);
    CHECK(q.dropped() == 6);
    CHECK(drain(q) == std::vector<std::string>{"6", "7", "8", "9"});
}

TEST_CASE("replies are never dropped and do not count against the message bound", "[bridge]") {
    SendQueue q(2, 1024);
    q.push(reply("serverInfo"));
    for (int i = 0; i < 5; ++i)
        q.push(message(i));
    q.push(reply("status"));
    q.push(message(5));
    CHECK(drain(q) == std::vector<std::string>{"serverInfo", "4", "status", "5"}); // the order kept
    CHECK(q.dropped() == 4);
}

TEST_CASE("the frame being written stays until its write completes", "[bridge]") {
    SendQueue q(2, 1024);
    q.push(message(0));
    q.push(message(1));
    CHECK(*q.start_front().bytes == "0");
    CHECK(q.writing());
    q.push(message(2)); // full: drops 1, not 0 (in flight)
    q.pop_front();
    CHECK_FALSE(q.writing());
    CHECK(drain(q) == std::vector<std::string>{"2"});
}

TEST_CASE("replies past their byte bound are refused, and counted out as they are written", "[bridge]") {
    SendQueue q(2, 10);
    CHECK(q.push(reply("12345")));
    CHECK(q.push(reply("6789")));
    CHECK(q.reply_bytes() == 9);
    CHECK_FALSE(q.push(reply("ab"))); // 11 bytes: over the bound, not queued
    CHECK(q.push(message(0)));        // messages are not replies
    CHECK(q.size() == 3);
    q.start_front();
    q.pop_front();
    CHECK(q.reply_bytes() == 4);
    CHECK(q.push(reply("ab")));
}

TEST_CASE("a client being closed keeps only the frame in flight", "[bridge]") {
    SendQueue q(4, 100);
    q.push(reply("serverInfo"));
    q.push(message(0));
    q.push(reply("status"));
    CHECK(*q.start_front().bytes == "serverInfo");
    q.clear_waiting();
    CHECK(q.size() == 1);
    CHECK(q.reply_bytes() == 10);
    q.pop_front();
    CHECK(q.empty());
    CHECK(q.reply_bytes() == 0);
}
