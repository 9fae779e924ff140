#include "tools/bridge/command_link.hpp"

#include "dbus/vehicle_names.hpp"
#include "tools/client/client.hpp"

#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace caracara::bridge {

namespace names = caracara::dbus;

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

// What a reply needs to report a refusal; freed with the call's slot (sd-bus destroy callback).
struct CommandLink::Pending {
    CommandLink* link;
    CommandKind kind;
    bool quiet;
};

CommandLink::CommandLink(boost::asio::io_context& io, const caracara::dbus::BusChoice& bus, Refused on_refused,
                         Answered on_answered, std::function<void()> on_lost)
    : on_refused_(std::move(on_refused)), on_answered_(std::move(on_answered)) {
    if (const int r = caracara::dbus::open_bus(bus, "caracara-bridge-pilot", bus_); r < 0)
        throw std::runtime_error(std::string("cannot connect to the bus: ") + std::strerror(-r));
    watch_ = std::make_unique<BusWatch>(io, bus_.get(), std::move(on_lost));
}

CommandLink::~CommandLink() {
    // Replies still pending are dropped with the connection (their slots are floating and
    // freed with the bus); the watch goes first so nothing runs while the bus closes.
    watch_.reset();
}

std::string CommandLink::unique_name() const {
    const char* name = nullptr;
    return sd_bus_get_unique_name(bus_.get(), &name) >= 0 && name ? name : "";
}

int CommandLink::on_reply(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* p = static_cast<Pending*>(userdata);
    const CommandSpec& spec = command_spec(p->kind);
    if (sd_bus_message_is_method_error(m, nullptr)) {
        if (p->quiet)
            return 0;
        const sd_bus_error* e = sd_bus_message_get_error(m);
        p->link->on_refused_(spec.topic, e && e->name ? e->name : "", e && e->message ? e->message : "");
        return 0;
    }
    switch (spec.reply) {
    case CommandReply::None: break;
    case CommandReply::Directions:
        try {
            p->link->on_answered_(spec.topic, directions_json(m));
        } catch (const caracara::client::Failure& f) {
            p->link->on_refused_(spec.topic, "org.caracara.Bridge.Error.BadReply", f.message);
        }
        break;
    }
    return 0;
}

void CommandLink::send(const Command& c, bool quiet) {
    const CommandSpec& spec = command_spec(c.kind);
    sd_bus_message* raw = nullptr;
    int r = sd_bus_message_new_method_call(bus_.get(), &raw, names::kBusName, names::kRootPath, names::kVehicleIface,
                                           spec.member);
    caracara::dbus::MessagePtr call(raw);
    if (r >= 0)
        r = sd_bus_message_set_auto_start(call.get(), 0);
    for (const CommandArg& arg : c.args)
        if (r >= 0)
            r = std::visit(Append{call.get()}, arg);
    auto* pending = new Pending{this, c.kind, quiet};
    sd_bus_slot* slot = nullptr;
    const auto timeout_us = static_cast<uint64_t>(std::chrono::microseconds(spec.timeout).count());
    if (r >= 0)
        r = sd_bus_call_async(bus_.get(), &slot, call.get(), on_reply, pending, timeout_us);
    if (r < 0) {
        delete pending;
        on_refused_(spec.topic, "org.caracara.Bridge.Error.SendFailed", std::strerror(-r));
        return;
    }
    // The slot floats (the bus owns it: freed after the reply or with the bus) and frees
    // `pending` with it; the reference sd_bus_call_async gave us is dropped.
    sd_bus_slot_set_destroy_callback(slot, [](void* p) { delete static_cast<Pending*>(p); });
    sd_bus_slot_set_floating(slot, 1);
    sd_bus_slot_unref(slot);
    watch_->kick();
}

} // namespace caracara::bridge
