#include "tools/bridge/seat_gate.hpp"

#include "tools/bridge/client_protocol.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

namespace caracara::bridge {

void SeatGate::join() {
    const std::weak_ptr<SeatGate*> weak = alive_;
    id_ = seat_.join(
        [weak](const PilotSeat::News& n) {
            if (auto g = weak.lock())
                (*g)->told(n);
        },
        [weak] {
            if (auto g = weak.lock(); g && (*g)->id_)
                (*g)->lost();
        });
}

void SeatGate::leave() {
    if (id_)
        seat_.leave(*id_);
    id_.reset(); // nothing more: no command, no loss
}

void SeatGate::told(const PilotSeat::News& n) {
    refusal_logged_.clear(); // a new refusal after a change is logged again
    const nlohmann::json j{{"holder", n.holder}, {"yours", n.yours}, {"change", std::string(name_of(n.change))}, {"by", n.by}};
    actions_.send_text(status_json(0, j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                                   command_topic_name(CommandKind::Seat)));
}

void SeatGate::lost() {
    std::fprintf(stderr, "caracara-bridge: %s lost the pilot's seat to a take-over: its commands end with its bus connection\n",
                 me().c_str());
    // The old connection goes: caracarad zeroes what it commanded, ends its motor test or detection.
    actions_.renew_link();
}

void SeatGate::refuse(std::string_view topic, const std::string& error, const std::string& why) {
    const std::string text = std::string(topic) + " refused: org.caracara.Bridge.Error." + error + ": " + why;
    actions_.send_text(status_json(2, text));
    // Logged once per holder and topic: a teleop panel refused at 20 Hz is one line, not twenty a second.
    const std::string key = (seat_.holder() ? seat_.label(*seat_.holder()) : "") + "|" + std::string(topic);
    if (refusal_logged_ == key)
        return;
    refusal_logged_ = key;
    std::fprintf(stderr, "caracara-bridge: %s: %s (logged once until the seat changes)\n", me().c_str(), text.c_str());
}

bool SeatGate::allows(const Command& c) {
    const CommandSpec& spec = command_spec(c.kind);
    if (!id_)
        return false;
    if (spec.seat == CommandSeat::Anyone)
        return true;
    const PilotSeat::Answer a = seat_.command(*id_);
    if (!a.ok)
        refuse(spec.topic, "SeatTaken",
               "the pilot's seat is held by " + a.holder + "; take it over with /command/seat {\"action\":\"take-over\"} (docs/foxglove.md)");
    return a.ok;
}

void SeatGate::ask(const Command& c) {
    if (!id_)
        return;
    const std::string_view topic = command_topic_name(CommandKind::Seat);
    const auto action = parse_name<SeatAction>(std::get<std::string>(c.args.at(0)));
    if (const std::string& name = std::get<std::string>(c.args.at(1)); !name.empty())
        seat_.name(*id_, name);
    const std::optional<PilotSeat::ClientId> before = seat_.holder();
    switch (*action) {
    case SeatAction::Claim:
        if (const PilotSeat::Answer a = seat_.ask(*id_, SeatAction::Claim); !a.ok)
            refuse(topic, "SeatTaken", "the pilot's seat is held by " + a.holder + "; only \"take-over\" takes it from its holder");
        return;
    case SeatAction::TakeOver:
        if (before && *before != *id_) {
            // The vehicle held at zero by the new holder before the old one's connection goes, so it
            // is a pilot at once (no pilot-lost kill for the handover); refused when killed or
            // surfacing, where nothing is driven anyway.
            actions_.send_quiet(Command{CommandKind::Motion, {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}});
            std::fprintf(stderr, "caracara-bridge: the pilot's seat: %s took it over from %s\n", me().c_str(),
                         seat_.label(*before).c_str());
        }
        seat_.ask(*id_, SeatAction::TakeOver);
        return;
    case SeatAction::Release:
        if (const PilotSeat::Answer a = seat_.ask(*id_, SeatAction::Release); !a.ok) {
            refuse(topic, "NotSeatHolder", a.holder.empty() ? "the pilot's seat is free" : "the pilot's seat is held by " + a.holder);
            return;
        }
        std::fprintf(stderr, "caracara-bridge: the pilot's seat: %s released it\n", me().c_str());
        // Released: what it commanded goes with its connection, as when it leaves.
        actions_.renew_link();
        return;
    }
}

} // namespace caracara::bridge
