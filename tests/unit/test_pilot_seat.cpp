// caracara-bridge's pilot's seat (tools/bridge/pilot_seat.hpp): one holder; a free seat taken by
// a claim (a first command), a held one only by a take-over, which its holder hears of first;
// every client told each change; the seat free once its holder releases it or leaves. And a
// client's side of it (tools/bridge/seat_gate.hpp).
#include "tests/catch.hpp"
#include "tools/bridge/command.hpp"
#include "tools/bridge/pilot_seat.hpp"
#include "tools/bridge/seat_gate.hpp"

#include <string>
#include <vector>

using caracara::bridge::CommandKind;
using caracara::bridge::PilotSeat;
using caracara::bridge::SeatAction;
using caracara::bridge::SeatChange;

namespace {

struct Heard {
    std::vector<PilotSeat::News> news;
    int lost = 0;
    std::vector<std::string>* order = nullptr; // who heard what first, across clients
};

PilotSeat::ClientId join(PilotSeat& seat, Heard& h, std::string tag, std::vector<std::string>* order = nullptr) {
    h.order = order;
    return seat.join(
        [&h, tag](const PilotSeat::News& n) {
            h.news.push_back(n);
            if (h.order)
                h.order->push_back(tag + " told");
        },
        [&h, tag] {
            ++h.lost;
            if (h.order)
                h.order->push_back(tag + " lost");
        });
}

} // namespace

TEST_CASE("a free seat goes to the first client that commands; another is refused with the holder's name", "[bridge]") {
    PilotSeat seat;
    Heard a, b;
    const auto ida = join(seat, a, "a");
    const auto idb = join(seat, b, "b");
    REQUIRE(a.news.size() == 1);
    CHECK(a.news[0].holder.empty());
    CHECK(a.news[0].change == SeatChange::Now);
    seat.name(idb, "cockpit, Linux x86_64");
    CHECK(seat.command(idb).ok);
    CHECK(seat.holder() == idb);
    CHECK(a.news.back().holder == "client #2 (cockpit, Linux x86_64)");
    CHECK_FALSE(a.news.back().yours);
    CHECK(b.news.back().yours);
    CHECK(b.news.back().change == SeatChange::Claimed);
    const PilotSeat::Answer refused = seat.command(ida);
    CHECK_FALSE(refused.ok);
    CHECK(refused.holder == "client #2 (cockpit, Linux x86_64)");
    CHECK_FALSE(seat.ask(ida, SeatAction::Claim).ok); // a claim takes nothing from a holder
    CHECK_FALSE(seat.ask(ida, SeatAction::Release).ok);
    CHECK(seat.holder() == idb);
    CHECK(b.lost == 0);
}

TEST_CASE("a take-over is explicit: the holder loses it first, then everyone hears who took it", "[bridge]") {
    PilotSeat seat;
    std::vector<std::string> order;
    Heard a, b, c;
    const auto ida = join(seat, a, "a", &order);
    const auto idb = join(seat, b, "b", &order);
    join(seat, c, "c", &order);
    REQUIRE(seat.command(ida).ok);
    order.clear();
    const PilotSeat::Answer t = seat.ask(idb, SeatAction::TakeOver);
    CHECK(t.ok);
    CHECK(t.took_from_another);
    CHECK(a.lost == 1);
    REQUIRE(!order.empty());
    CHECK(order.front() == "a lost");
    CHECK(a.news.back().change == SeatChange::TakenOver);
    CHECK(a.news.back().by == "client #2");
    CHECK_FALSE(a.news.back().yours);
    CHECK(c.news.back().holder == "client #2");
    CHECK_FALSE(seat.command(ida).ok);
    // A take-over of a free seat is a claim; of one's own, nothing.
    seat.leave(idb);
    CHECK_FALSE(seat.holder());
    CHECK(a.news.back().change == SeatChange::Left);
    CHECK(a.news.back().holder.empty());
    const PilotSeat::Answer free = seat.ask(ida, SeatAction::TakeOver);
    CHECK(free.ok);
    CHECK_FALSE(free.took_from_another);
    CHECK(a.news.back().change == SeatChange::Claimed);
    CHECK_FALSE(seat.ask(ida, SeatAction::TakeOver).took_from_another);
    CHECK(a.lost == 1);
}

TEST_CASE("released or left, the seat is free and said so", "[bridge]") {
    PilotSeat seat;
    Heard a, b;
    const auto ida = join(seat, a, "a");
    const auto idb = join(seat, b, "b");
    REQUIRE(seat.command(ida).ok);
    CHECK(seat.ask(ida, SeatAction::Release).ok);
    CHECK_FALSE(seat.holder());
    CHECK(b.news.back().change == SeatChange::Released);
    CHECK(b.news.back().holder.empty());
    CHECK(a.lost == 0); // releasing is no loss to a take-over
    REQUIRE(seat.command(idb).ok);
    seat.leave(ida); // not the holder: nothing changes
    CHECK(seat.holder() == idb);
    seat.leave(idb);
    CHECK_FALSE(seat.holder());
    CHECK_FALSE(seat.command(idb).ok); // gone: no seat for it
}

TEST_CASE("/command/seat's JSON: an action by name, a printable name of 64 characters at most", "[bridge]") {
    using caracara::bridge::parse_command;
    const auto ok = parse_command(CommandKind::Seat, R"({"action":"take-over","name":"cockpit"})");
    REQUIRE(ok.command);
    CHECK(std::get<std::string>(ok.command->args[0]) == "take-over");
    CHECK(std::get<std::string>(ok.command->args[1]) == "cockpit");
    CHECK(parse_command(CommandKind::Seat, R"({"action":"claim"})").command);
    CHECK(parse_command(CommandKind::Seat, R"({"action":"grab"})").error ==
          R"(seat needs 'action': "claim", "take-over" or "release")");
    CHECK(parse_command(CommandKind::Seat, R"({"action":"claim","force":true})").error ==
          R"(seat takes "action" and "name", not 'force')");
    CHECK_FALSE(parse_command(CommandKind::Seat, R"({"action":"claim","name":"a\nb"})").command);
    CHECK_FALSE(parse_command(CommandKind::Seat, R"({"action":"claim","name":")" + std::string(65, 'x') + "\"}").command);
    CHECK_FALSE(PilotSeat::valid_name("\x7f"));
    CHECK(PilotSeat::valid_name(std::string(64, 'x')));
}

TEST_CASE("every command but Kill and the seat's own needs the seat", "[bridge]") {
    using caracara::bridge::command_spec;
    using caracara::bridge::CommandSeat;
    for (auto k = 0; k <= static_cast<int>(CommandKind::Seat); ++k) {
        const auto kind = static_cast<CommandKind>(k);
        const bool anyone = kind == CommandKind::Kill || kind == CommandKind::Seat;
        INFO(std::string(command_spec(kind).topic));
        CHECK((command_spec(kind).seat == CommandSeat::Anyone) == anyone);
    }
}

// A client's side of the seat (tools/bridge/seat_gate.hpp): what it lets through, what it tells.
namespace {

struct Client {
    std::vector<std::string> texts;  // status messages sent to it
    std::vector<std::string> events; // "zero" (its quiet zero motion), "renew" (its connection replaced)
    caracara::bridge::SeatGate gate;
    explicit Client(PilotSeat& seat)
        : gate(seat, {[this](std::string t) { texts.push_back(std::move(t)); },
                      [this](const caracara::bridge::Command& c) {
                          CHECK(c.kind == CommandKind::Motion);
                          for (const auto& a : c.args)
                              CHECK(std::get<double>(a) == 0.0);
                          events.push_back("zero");
                      },
                      [this] { events.push_back("renew"); }}) {}
};

caracara::bridge::Command cmd(CommandKind k, std::string_view json) { return *caracara::bridge::parse_command(k, json).command; }

} // namespace

TEST_CASE("a gate lets the holder's commands through, refuses another's by name, lets any kill through", "[bridge]") {
    PilotSeat seat;
    Client a(seat), b(seat);
    a.gate.join();
    b.gate.join();
    REQUIRE(a.texts.size() == 1);
    CHECK(a.texts[0] == R"({"id":"/command/seat","level":0,"message":"{\"by\":\"\",\"change\":\"now\",\"holder\":\"\",\"yours\":false}","op":"status"})");
    CHECK(a.gate.allows(cmd(CommandKind::Drive, R"({"forward":0.5})"))); // a free seat: taken
    CHECK_FALSE(b.gate.allows(cmd(CommandKind::Motion, "{}")));
    CHECK(b.texts.back().find(R"(/command/motion refused: org.caracara.Bridge.Error.SeatTaken: the pilot's seat is held by client #1)") !=
          std::string::npos);
    CHECK(b.gate.allows(cmd(CommandKind::Kill, "{}")));
    // The take-over: the new holder's zero first, then the old holder's connection replaced.
    b.gate.ask(cmd(CommandKind::Seat, R"({"action":"take-over","name":"teleop"})"));
    CHECK(b.events == std::vector<std::string>{"zero"});
    CHECK(a.events == std::vector<std::string>{"renew"});
    CHECK(a.texts.back().find(R"(\"change\":\"taken-over\")") != std::string::npos);
    CHECK(a.texts.back().find(R"(\"by\":\"client #2 (teleop)\")") != std::string::npos);
    CHECK_FALSE(a.gate.allows(cmd(CommandKind::ClearKill, "{}")));
    // Released by its holder: its connection replaced, the seat free; a release by another refused.
    a.gate.ask(cmd(CommandKind::Seat, R"({"action":"release"})"));
    CHECK(a.texts.back().find("NotSeatHolder") != std::string::npos);
    b.gate.ask(cmd(CommandKind::Seat, R"({"action":"release"})"));
    CHECK(b.events == std::vector<std::string>{"zero", "renew"});
    CHECK_FALSE(seat.holder());
    // Gone: nothing more through it, and a gate destroyed is never called.
    b.gate.leave();
    CHECK_FALSE(b.gate.allows(cmd(CommandKind::Kill, "{}")));
    {
        Client c(seat);
        c.gate.join();
    }
    CHECK(a.gate.allows(cmd(CommandKind::Drive, "{}"))); // every client told: none gone wrong
}
