// One WebSocket client's side of the Foxglove WebSocket protocol v1 (subprotocol
// foxglove.websocket.v1; the spec of the foxglove/ws-protocol repository, docs/spec.md), as
// pure code: a frame in, what to answer and what to command out. No I/O, so the fuzzer
// (fuzz/fuzz_bridge.cpp) drives exactly what the bridge runs.
//
//   text:   {"op":"subscribe","subscriptions":[{"id":N,"channelId":C}]}, "unsubscribe"
//           {"subscriptionIds":[N]}, client "advertise" {"channels":[{id,topic,encoding,
//           schemaName}]}, "unadvertise" {"channelIds":[N]}
//   binary: 0x01, u32 client channel id (little-endian), the message (JSON on a command topic)
//
// Anything else is answered with a status message (level error) and changes nothing.
#pragma once

#include "tools/bridge/command.hpp"

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace caracara::bridge {

// A status message: {"op":"status","level":L,"message":M}; level 0 info, 1 warning, 2 error.
// With an id ({"id":I}): a command's answer, I its topic (docs/foxglove.md).
std::string status_json(int level, std::string_view message, std::string_view id = {});

struct Outcome {
    std::vector<std::string> replies;   // text frames to send (status messages)
    std::optional<Command> command;     // a command to send to caracarad
    std::vector<uint32_t> subscribed;   // channels just subscribed to (sent their latest message)
};

class ClientProtocol {
public:
    static constexpr std::size_t kMaxSubscriptions = 256;
    static constexpr std::size_t kMaxClientChannels = 32;

    // channel_count: the server channels advertised, ids 1..channel_count.
    explicit ClientProtocol(std::size_t channel_count) : channel_count_(channel_count) {}

    // The server's greeting to a client once upgraded: serverInfo (clientPublish, JSON) and the
    // advertise of every channel of foxglove::channels() (ids from 1, in its order).
    static std::string server_info();
    static std::string advertise();

    Outcome on_text(std::string_view text);
    Outcome on_binary(std::span<const uint8_t> bytes);

    // The subscription ids on a server channel (id 1..channel_count).
    const std::vector<uint32_t>& subscribers(uint32_t channel_id) const;
    std::size_t subscription_count() const { return subscriptions_.size(); }

private:
    std::size_t channel_count_;
    std::map<uint32_t, uint32_t> subscriptions_;               // subscription id -> channel id
    std::map<uint32_t, std::vector<uint32_t>> by_channel_;     // channel id -> subscription ids
    std::map<uint32_t, CommandKind> client_channels_;          // client channel id -> command
};

} // namespace caracara::bridge
