// caracara-bridge's handling of a client's frames (tools/bridge/client_protocol.hpp), as one
// WebSocket client could send them: text frames (the protocol's JSON ops) and binary frames
// (client message data), in any order. Invariants: nothing crashes or leaks; every reply is a
// status message (valid JSON, op "status", level error); a frame yields either replies or a
// command, never both; a command comes only from a binary client-message-data frame (opcode 1,
// a whole header) and holds only what the D-Bus call can carry (8 thrust values, finite axes,
// LED bytes, a profile name without NUL); subscriptions stay within the limit and on
// advertised channels.
//
// Input: frames, each [u8 kind][u16 length][that many bytes], to the end; kind's low bit set
// makes a binary frame.
#include "fuzz/byte_source.hpp"
#include "fuzz/check.hpp"
#include "tools/bridge/client_protocol.hpp"
#include "tools/foxglove/channels.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

using caracara::bridge::ClientProtocol;
using caracara::bridge::CommandKind;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    caracara::fuzz::ByteSource in(data, size);
    const std::size_t channels = caracara::foxglove::channels().size();
    ClientProtocol p(channels);
    while (!in.empty()) {
        const bool binary = in.u8() & 1;
        const auto frame = in.bytes(in.u16());
        const caracara::bridge::Outcome o =
            binary ? p.on_binary(frame) : p.on_text({reinterpret_cast<const char*>(frame.data()), frame.size()});
        for (const std::string& reply : o.replies) {
            const auto j = nlohmann::json::parse(reply, nullptr, false);
            FUZZ_CHECK(!j.is_discarded() && j.is_object(), "a reply that is not JSON: %s", reply.c_str());
            FUZZ_CHECK(j["op"] == "status" && j["level"] == 2, "a reply that is no error status: %s", reply.c_str());
        }
        if (o.command) {
            FUZZ_CHECK(o.replies.empty(), "a command with an error");
            FUZZ_CHECK(binary && frame.size() >= 5 && frame[0] == 1, "a command from a frame that is no message data");
            const auto& c = *o.command;
            if (c.kind == CommandKind::Thrust)
                FUZZ_CHECK(c.args.size() == 1 && std::get<std::vector<int32_t>>(c.args[0]).size() == 8,
                           "thrust without its 8 values");
            if (c.kind == CommandKind::Motion || c.kind == CommandKind::Drive) {
                FUZZ_CHECK(c.args.size() == 6, "motion with %zu axes", c.args.size());
                for (const auto& a : c.args)
                    FUZZ_CHECK(std::isfinite(std::get<double>(a)), "a motion axis that is not finite");
            }
            if (c.kind == CommandKind::Profile)
                FUZZ_CHECK(std::get<std::string>(c.args.at(0)).find('\0') == std::string::npos, "a profile name with NUL");
            if (c.kind == CommandKind::MotorTest)
                FUZZ_CHECK(c.args.size() == 2 && std::holds_alternative<int32_t>(c.args[1]), "a motor test without (ii)");
        } else {
            FUZZ_CHECK(!o.replies.empty() || !binary, "a binary frame that was neither a command nor refused");
        }
        for (const uint32_t ch : o.subscribed)
            FUZZ_CHECK(ch >= 1 && ch <= channels, "subscribed to channel %u", ch);
        FUZZ_CHECK(p.subscription_count() <= ClientProtocol::kMaxSubscriptions, "%zu subscriptions",
                   p.subscription_count());
    }
    return 0;
}
