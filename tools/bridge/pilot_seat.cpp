#include "tools/bridge/pilot_seat.hpp"

#include <vector>

namespace caracara::bridge {

PilotSeat::ClientId PilotSeat::join(Tell tell, std::function<void()> lost) {
    const ClientId id = next_++;
    Client& c = clients_[id] = Client{"", std::move(tell), std::move(lost)};
    c.tell({holder_ ? label(*holder_) : "", false, SeatChange::Now, ""});
    return id;
}

void PilotSeat::leave(ClientId id) {
    const auto it = clients_.find(id);
    if (it == clients_.end())
        return;
    if (holder_ == id) {
        holder_.reset();
        tell_all(SeatChange::Left, id);
    }
    clients_.erase(id);
}

void PilotSeat::name(ClientId id, std::string name) {
    if (const auto it = clients_.find(id); it != clients_.end() && valid_name(name))
        it->second.name = std::move(name);
}

bool PilotSeat::valid_name(const std::string& name) {
    if (name.size() > kMaxName)
        return false;
    for (const char c : name)
        if (c < 0x20 || c > 0x7e)
            return false;
    return true;
}

std::string PilotSeat::label(ClientId id) const {
    const auto it = clients_.find(id);
    std::string out = "client #" + std::to_string(id);
    if (it != clients_.end() && !it->second.name.empty())
        out += " (" + it->second.name + ")";
    return out;
}

PilotSeat::Answer PilotSeat::ask(ClientId id, SeatAction action) {
    if (!clients_.contains(id))
        return {false, false, holder_ ? label(*holder_) : ""};
    switch (action) {
    case SeatAction::Claim:
        if (holder_ == id)
            return {true, false, label(id)};
        if (holder_)
            return {false, false, label(*holder_)};
        holder_ = id;
        tell_all(SeatChange::Claimed, id);
        return {true, false, label(id)};
    case SeatAction::TakeOver: {
        if (holder_ == id)
            return {true, false, label(id)};
        const std::optional<ClientId> from = holder_;
        holder_ = id;
        // The one that lost it first: its commands stop before anyone hears of the new holder.
        if (from)
            if (const auto it = clients_.find(*from); it != clients_.end() && it->second.lost)
                it->second.lost();
        tell_all(from ? SeatChange::TakenOver : SeatChange::Claimed, id);
        return {true, from.has_value(), label(id)};
    }
    case SeatAction::Release:
        if (holder_ != id)
            return {false, false, holder_ ? label(*holder_) : ""};
        holder_.reset();
        tell_all(SeatChange::Released, id);
        return {true, false, ""};
    }
    return {};
}

void PilotSeat::tell_all(SeatChange change, ClientId by) {
    const std::string holder = holder_ ? label(*holder_) : "";
    const std::string who = label(by);
    // A copy of the tellers: one may end its session (and leave) while being told.
    std::vector<std::pair<ClientId, Tell>> tellers;
    for (const auto& [id, c] : clients_)
        tellers.emplace_back(id, c.tell);
    for (const auto& [id, tell] : tellers)
        if (tell)
            tell({holder, holder_ == id, change, who});
}

} // namespace caracara::bridge
