// The pilot's seat (docs/foxglove.md, "The pilot's seat"): of the bridge's clients, one at a time
// may command the vehicle; any may kill. A client's first command that needs the seat takes it
// when it is free ("claim"); a held seat changes hands only by an explicit "take-over", which its
// holder is told of at once, or when its holder releases it or leaves. Every client is told who
// holds it when it joins and at each change. Pure logic: the sessions act on it (the one that
// lost the seat drops its D-Bus connection, so caracarad zeroes what it commanded).
#pragma once

#include "core/enum_names.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

namespace caracara::bridge {

// What a client asks of the seat on /command/seat.
enum class SeatAction : uint8_t { Claim, TakeOver, Release };
// What a client is told of: the seat as it is when it joins, or a change.
enum class SeatChange : uint8_t { Now, Claimed, TakenOver, Released, Left };

} // namespace caracara::bridge

namespace caracara {

template <>
struct EnumNames<bridge::SeatAction> {
    static constexpr std::array<EnumName<bridge::SeatAction>, 3> table{{
        {bridge::SeatAction::Claim, "claim"},
        {bridge::SeatAction::TakeOver, "take-over"},
        {bridge::SeatAction::Release, "release"},
    }};
};

template <>
struct EnumNames<bridge::SeatChange> {
    static constexpr std::array<EnumName<bridge::SeatChange>, 5> table{{
        {bridge::SeatChange::Now, "now"},
        {bridge::SeatChange::Claimed, "claimed"},
        {bridge::SeatChange::TakenOver, "taken-over"},
        {bridge::SeatChange::Released, "released"},
        {bridge::SeatChange::Left, "left"},
    }};
};

} // namespace caracara

namespace caracara::bridge {

class PilotSeat {
public:
    using ClientId = uint64_t;

    // What one client is told: who holds the seat ("" free), whether it is this client, what
    // changed and who changed it (the client that claimed, took over, released or left).
    struct News {
        std::string holder;
        bool yours = false;
        SeatChange change = SeatChange::Now;
        std::string by;
    };
    using Tell = std::function<void(const News&)>;

    struct Answer {
        bool ok = false;
        bool took_from_another = false; // a take-over of a seat another client held
        std::string holder;             // when refused: who holds it
    };

    // A new client, numbered from 1; told the seat at once. lost: called when another client
    // takes the seat over from it (not when it releases it or leaves).
    ClientId join(Tell tell, std::function<void()> lost);
    // The client is gone: the seat is free when it held it, and the others are told.
    void leave(ClientId id);
    // The client's name in words, shown to the others ("" : none given).
    void name(ClientId id, std::string name);
    // A command that needs the seat from `id`: ok when it holds it, or the seat was free (then it
    // is its now: a claim).
    Answer command(ClientId id) { return ask(id, SeatAction::Claim); }
    Answer ask(ClientId id, SeatAction action);

    std::optional<ClientId> holder() const { return holder_; }
    // "client #3 (cockpit, Linux x86_64)": its number, and its name when it gave one.
    std::string label(ClientId id) const;
    // A client's name: up to kMaxName printable ASCII characters.
    static constexpr std::size_t kMaxName = 64;
    static bool valid_name(const std::string& name);

private:
    struct Client {
        std::string name;
        Tell tell;
        std::function<void()> lost;
    };
    void tell_all(SeatChange change, ClientId by);

    std::map<ClientId, Client> clients_;
    std::optional<ClientId> holder_;
    ClientId next_ = 1;
};

} // namespace caracara::bridge
