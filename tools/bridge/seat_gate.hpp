// One client's side of the pilot's seat (PilotSeat, docs/foxglove.md "The pilot's seat"): which
// of its commands go to caracarad (a command that needs the seat takes it when free; without it,
// refused with org.caracara.Bridge.Error.SeatTaken and the holder's name, logged once per holder),
// its /command/seat asks, and the seat as it is told to it (a status whose id is the seat's
// topic). Its Session does what it asks: send a text, send a command on its own D-Bus connection
// (a zero motion before a take-over), replace that connection when it lost or released the seat.
#pragma once

#include "tools/bridge/command.hpp"
#include "tools/bridge/pilot_seat.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace caracara::bridge {

class SeatGate {
public:
    struct Actions {
        std::function<void(std::string)> send_text; // a text frame to this client
        std::function<void(const Command&)> send_quiet; // on this client's connection, a refusal not told
        std::function<void()> renew_link;           // this client's connection replaced by a new one
    };

    SeatGate(PilotSeat& seat, Actions actions) : seat_(seat), actions_(std::move(actions)) {}

    // Joins the seat's clients (the seat's callbacks to this gate end with it).
    void join();
    // This client left: the seat is free when it held it, the others told.
    void leave();
    bool joined() const { return id_.has_value(); }
    // True when the command may go to caracarad; else it was refused here.
    bool allows(const Command& c);
    // A /command/seat from this client.
    void ask(const Command& c);

private:
    // What the seat told this client, sent to it.
    void told(const PilotSeat::News& news);
    // Another client took the seat over: logged; this client's connection is replaced.
    void lost();
    void refuse(std::string_view topic, const std::string& error, const std::string& why);
    std::string me() const { return seat_.label(*id_); }

    PilotSeat& seat_;
    Actions actions_;
    std::optional<PilotSeat::ClientId> id_;
    std::string refusal_logged_; // the holder and topic of the refusal last logged
    std::shared_ptr<SeatGate*> alive_ = std::make_shared<SeatGate*>(this); // the seat's callbacks hold it weakly
};

} // namespace caracara::bridge
