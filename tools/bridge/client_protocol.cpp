#include "tools/bridge/client_protocol.hpp"

#include "tools/foxglove/channels.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace caracara::bridge {

using nlohmann::json;

namespace {

constexpr uint8_t kClientMessageData = 0x01;

Outcome error(std::string_view message) { return {{status_json(2, message)}, std::nullopt, {}}; }

bool is_u32(const json& v) { return v.is_number_unsigned() && v.get<uint64_t>() <= UINT32_MAX; }

} // namespace

std::string status_json(int level, std::string_view message, std::string_view id) {
    json j{{"op", "status"}, {"level", level}, {"message", std::string(message)}};
    if (!id.empty())
        j["id"] = std::string(id);
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string ClientProtocol::server_info() {
    return nlohmann::json{{"op", "serverInfo"},
                          {"name", "caracara-bridge"},
                          {"capabilities", {"clientPublish"}},
                          {"supportedEncodings", {"json"}},
                          {"metadata", nlohmann::json::object()}}
        .dump();
}

std::string ClientProtocol::advertise() {
    nlohmann::json list = nlohmann::json::array();
    const auto& all = foxglove::channels();
    for (std::size_t i = 0; i < all.size(); ++i)
        list.push_back({{"id", i + 1},
                        {"topic", all[i].topic},
                        {"encoding", foxglove::kEncoding},
                        {"schemaName", all[i].schema_name},
                        {"schema", all[i].schema},
                        {"schemaEncoding", foxglove::kSchemaEncoding}});
    return nlohmann::json{{"op", "advertise"}, {"channels", list}}.dump();
}

const std::vector<uint32_t>& ClientProtocol::subscribers(uint32_t channel_id) const {
    static const std::vector<uint32_t> none;
    const auto it = by_channel_.find(channel_id);
    return it == by_channel_.end() ? none : it->second;
}

Outcome ClientProtocol::on_text(std::string_view text) {
    const json j = json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded() || !j.is_object())
        return error("malformed message: not a JSON object");
    const auto op = j.find("op");
    if (op == j.end() || !op->is_string())
        return error("malformed message: no \"op\"");
    const std::string& name = op->get_ref<const std::string&>();
    Outcome out;
    if (name == "subscribe") {
        const auto subs = j.find("subscriptions");
        if (subs == j.end() || !subs->is_array())
            return error("subscribe needs \"subscriptions\": an array");
        for (const json& s : *subs) {
            if (!s.is_object() || !s.contains("id") || !s.contains("channelId") || !is_u32(s["id"]) ||
                !is_u32(s["channelId"])) {
                out.replies.push_back(status_json(2, "subscribe: each subscription needs \"id\" and \"channelId\""));
                continue;
            }
            const auto id = s["id"].get<uint32_t>();
            const auto channel = s["channelId"].get<uint32_t>();
            if (channel == 0 || channel > channel_count_) {
                out.replies.push_back(status_json(2, "subscribe: unknown channel " + std::to_string(channel)));
            } else if (subscriptions_.contains(id)) {
                out.replies.push_back(status_json(2, "subscribe: subscription id " + std::to_string(id) + " is in use"));
            } else if (subscriptions_.size() >= kMaxSubscriptions) {
                out.replies.push_back(status_json(2, "subscribe: more than " + std::to_string(kMaxSubscriptions) +
                                                         " subscriptions"));
            } else {
                subscriptions_[id] = channel;
                by_channel_[channel].push_back(id);
                out.subscribed.push_back(channel);
            }
        }
        return out;
    }
    if (name == "unsubscribe") {
        const auto ids = j.find("subscriptionIds");
        if (ids == j.end() || !ids->is_array())
            return error("unsubscribe needs \"subscriptionIds\": an array");
        for (const json& v : *ids) {
            const auto it = is_u32(v) ? subscriptions_.find(v.get<uint32_t>()) : subscriptions_.end();
            if (it == subscriptions_.end()) {
                out.replies.push_back(status_json(2, "unsubscribe: no such subscription"));
                continue;
            }
            auto& list = by_channel_[it->second];
            list.erase(std::remove(list.begin(), list.end(), it->first), list.end());
            if (list.empty())
                by_channel_.erase(it->second);
            subscriptions_.erase(it);
        }
        return out;
    }
    if (name == "advertise") {
        const auto chans = j.find("channels");
        if (chans == j.end() || !chans->is_array())
            return error("advertise needs \"channels\": an array");
        for (const json& c : *chans) {
            if (!c.is_object() || !c.contains("id") || !is_u32(c["id"]) || !c.contains("topic") ||
                !c["topic"].is_string() || !c.contains("encoding") || !c["encoding"].is_string()) {
                out.replies.push_back(status_json(2, "advertise: each channel needs \"id\", \"topic\", \"encoding\""));
                continue;
            }
            const auto id = c["id"].get<uint32_t>();
            const std::string& topic = c["topic"].get_ref<const std::string&>();
            const auto kind = command_topic(topic);
            if (!kind)
                out.replies.push_back(status_json(2, "advertise: '" + topic + "' is no command topic (docs/foxglove.md)"));
            else if (c["encoding"] != "json")
                out.replies.push_back(status_json(2, "advertise: " + topic + " takes encoding \"json\""));
            else if (client_channels_.contains(id))
                out.replies.push_back(status_json(2, "advertise: client channel " + std::to_string(id) + " is in use"));
            else if (client_channels_.size() >= kMaxClientChannels)
                out.replies.push_back(status_json(2, "advertise: too many client channels"));
            else
                client_channels_[id] = *kind;
        }
        return out;
    }
    if (name == "unadvertise") {
        const auto ids = j.find("channelIds");
        if (ids == j.end() || !ids->is_array())
            return error("unadvertise needs \"channelIds\": an array");
        for (const json& v : *ids)
            if (!is_u32(v) || client_channels_.erase(v.get<uint32_t>()) == 0)
                out.replies.push_back(status_json(2, "unadvertise: no such client channel"));
        return out;
    }
    return error("unsupported op '" + name + "'");
}

Outcome ClientProtocol::on_binary(std::span<const uint8_t> bytes) {
    if (bytes.size() < 5)
        return error("malformed binary message: shorter than its header");
    if (bytes[0] != kClientMessageData)
        return error("unsupported binary opcode " + std::to_string(bytes[0]));
    const uint32_t id = uint32_t{bytes[1]} | uint32_t{bytes[2]} << 8 | uint32_t{bytes[3]} << 16 | uint32_t{bytes[4]} << 24;
    const auto it = client_channels_.find(id);
    if (it == client_channels_.end())
        return error("message on client channel " + std::to_string(id) + ", which is not advertised");
    const auto payload = bytes.subspan(5);
    CommandParse p = parse_command(it->second, {reinterpret_cast<const char*>(payload.data()), payload.size()});
    if (!p.command)
        return error(std::string(command_topic_name(it->second)) + ": " + p.error);
    return {{}, std::move(p.command), {}};
}

} // namespace caracara::bridge
