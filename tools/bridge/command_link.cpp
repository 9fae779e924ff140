#include "tools/bridge/command_link.hpp"

#include "tools/client/client.hpp"

#include <nlohmann/json.hpp>

namespace caracara::bridge {

namespace {

// Appends one argument by its type (CommandArg's D-Bus codes).
struct Append {
    sd_bus_message* m;
    int operator()(int32_t v) const { return sd_bus_message_append_basic(m, 'i', &v); }
    int operator()(uint8_t v) const { return sd_bus_message_append_basic(m, 'y', &v); }
    int operator()(double v) const { return sd_bus_message_append_basic(m, 'd', &v); }
    int operator()(const std::string& v) const { return sd_bus_message_append_basic(m, 's', v.c_str()); }
    int operator()(const std::vector<int32_t>& v) const {
        return sd_bus_message_append_array(m, 'i', v.data(), v.size() * sizeof(int32_t));
    }
};

// DetectDirections' a(sddddd)s: {"thrusters":[{thruster, verdict, yaw, pitch, roll, along,
// margin}], "fragment"}.
std::string directions_json(sd_bus_message* m) {
    namespace client = caracara::client;
    const client::Value rows = client::read_value(m);
    const client::Value fragment = client::read_value(m);
    nlohmann::json out{{"thrusters", nlohmann::json::array()}, {"fragment", fragment.s}};
    for (std::size_t i = 0; i < rows.items.size(); ++i) {
        const auto& f = rows.items[i].items;
        if (f.size() != 6)
            throw client::Failure{client::kExitUnavailable, "a malformed row"};
        out["thrusters"].push_back({{"thruster", i}, {"verdict", f[0].s}, {"yaw", f[1].number()},
                                    {"pitch", f[2].number()}, {"roll", f[3].number()}, {"along", f[4].number()},
                                    {"margin", f[5].number()}});
    }
    return out.dump();
}

} // namespace

CommandLink::CommandLink(boost::asio::io_context& io, const caracara::dbus::BusChoice& bus, Refused on_refused,
                         Answered on_answered, std::function<void()> on_lost)
    : connection_(bus, "caracara-bridge-pilot"), on_refused_(std::move(on_refused)),
      on_answered_(std::move(on_answered)) {
    watch_ = std::make_unique<BusWatch>(io, connection_.bus(), std::move(on_lost));
}

CommandLink::~CommandLink() {
    // Replies still pending are dropped with the connection (their slots are floating and
    // freed with the bus); the watch goes first so nothing runs while the bus closes.
    watch_.reset();
}

void CommandLink::replied(const CommandSpec& spec, bool quiet, const client::PilotConnection::Reply& reply) {
    if (!reply.ok()) {
        // quiet: the daemon's refusal is not told; a call that could not be sent always is.
        if (reply.error_name == client::PilotConnection::kSendFailed)
            on_refused_(spec.topic, "org.caracara.Bridge.Error.SendFailed", reply.error_message);
        else if (!quiet)
            on_refused_(spec.topic, reply.error_name, reply.error_message);
        return;
    }
    switch (spec.reply) {
    case CommandReply::None: break;
    case CommandReply::Directions:
        try {
            on_answered_(spec.topic, directions_json(reply.message));
        } catch (const caracara::client::Failure& f) {
            on_refused_(spec.topic, "org.caracara.Bridge.Error.BadReply", f.message);
        }
        break;
    }
}

void CommandLink::send(const Command& c, bool quiet) {
    const CommandSpec& spec = command_spec(c.kind);
    connection_.call(
        spec.member,
        [&](sd_bus_message* m) {
            int r = 0;
            for (const CommandArg& arg : c.args)
                if (r >= 0)
                    r = std::visit(Append{m}, arg);
            return r;
        },
        [this, &spec, quiet](const client::PilotConnection::Reply& reply) { replied(spec, quiet, reply); },
        std::chrono::duration_cast<std::chrono::microseconds>(spec.timeout));
    watch_->kick();
}

} // namespace caracara::bridge
