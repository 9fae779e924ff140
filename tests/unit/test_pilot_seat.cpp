// caracara-bridge's pilot's seat (tools/bridge/pilot_seat.hpp): one holder; a free seat taken by
// a claim (a first command), a held one only by a take-over, which its holder hears of first;
// every client told each change; the seat free once its holder releases it or leaves.
#include "tests/catch.hpp"
#include "tools/bridge/command.hpp"
#include "tools/bridge/pilot_seat.hpp"

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
