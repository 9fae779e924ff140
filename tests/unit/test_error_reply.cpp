// dbus/error_reply, the one error map: every Status's D-Bus name, and each way a handler
// replies (at once, later through a Completion, later with values), as a client on a private
// dbus-daemon receives it (ServiceRig's bus and loop, a test object of its own on a second
// connection).
#include "dbus/error_reply.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <cerrno>
#include <optional>
#include <set>
#include <string>

using namespace caracara;
using namespace caracara::test;

namespace {

constexpr const char* kName = "org.caracara.ErrorReplyTest";
constexpr const char* kPath = "/test";
constexpr const char* kIface = "org.caracara.ErrorReplyTest";

// What the handlers were given to answer later, and how.
struct Held {
    std::optional<Completion> later;
    int fill_result = 0;
    bool filled = false;
};

int m_ok(sd_bus_message* m, void*, sd_bus_error*) { return dbus::reply(m, Result{}); }
int m_refuse(sd_bus_message* m, void*, sd_bus_error*) {
    return dbus::reply(m, Result{Status::OutOfRange, "motor 9 is outside 0..7"});
}
int m_later(sd_bus_message* m, void* u, sd_bus_error*) {
    static_cast<Held*>(u)->later = dbus::reply_later(m);
    return 1;
}
int m_filled(sd_bus_message* m, void* u, sd_bus_error*) {
    auto* held = static_cast<Held*>(u);
    held->later = dbus::reply_filled_later(m, [held](sd_bus_message* out) {
        held->filled = true;
        return held->fill_result < 0 ? held->fill_result : sd_bus_message_append(out, "u", 42u);
    });
    return 1;
}

const sd_bus_vtable kVtable[] = {
    SD_BUS_VTABLE_START(0),
    SD_BUS_METHOD("Ok", "", "", m_ok, 0),
    SD_BUS_METHOD("Refuse", "", "", m_refuse, 0),
    SD_BUS_METHOD("Later", "", "", m_later, 0),
    SD_BUS_METHOD("Filled", "", "u", m_filled, 0),
    SD_BUS_VTABLE_END,
};

struct TestObject {
    explicit TestObject(ServiceRig& s) : bus(s.connect("error-reply-test")) {
        sd_bus_slot* sl = nullptr;
        if (sd_bus_add_object_vtable(bus.get(), &sl, kPath, kIface, kVtable, &held) < 0 ||
            sd_bus_request_name(bus.get(), kName, 0) < 0)
            throw std::runtime_error("cannot publish the test object");
        slot.reset(sl);
    }
    dbus::BusPtr bus;
    dbus::SlotPtr slot;
    Held held;
};

BusReply call(ServiceRig& s, const char* method) { return s.call_with(kPath, kIface, method, {}, nullptr, kName); }

// Calls `method`, which answers later: runs the loop until the handler holds the completion,
// then completes it with `result` and runs until the reply.
BusReply call_later(ServiceRig& s, TestObject& o, const char* method, const Result& result) {
    o.held.later.reset();
    sd_bus_message* m = nullptr;
    REQUIRE(sd_bus_message_new_method_call(s.client(), &m, kName, kPath, kIface, method) >= 0);
    dbus::MessagePtr msg(m);
    std::optional<BusReply> reply;
    sd_bus_slot* sl = nullptr;
    REQUIRE(sd_bus_call_async(s.client(), &sl, m, [](sd_bus_message* r, void* u, sd_bus_error*) {
        BusReply out;
        if (const sd_bus_error* e = sd_bus_message_get_error(r)) {
            out.error = e->name;
            out.message = e->message ? e->message : "";
        }
        out.reply.reset(sd_bus_message_ref(r));
        *static_cast<std::optional<BusReply>*>(u) = std::move(out);
        return 0;
    }, &reply, 0) >= 0);
    dbus::SlotPtr held(sl);
    REQUIRE(s.rig().run_until([&] { return o.held.later.has_value(); }));
    s.rig().run_for(20);
    CHECK_FALSE(reply.has_value()); // no reply before the completion
    (*o.held.later)(result);
    REQUIRE(s.rig().run_until([&] { return reply.has_value(); }));
    return std::move(*reply);
}

} // namespace

TEST_CASE("error_reply: every Status has its own org.caracara.Vehicle1.Error.<name>") {
    std::set<std::string> names;
    for (const auto& [status, name] : EnumNames<Status>::table) {
        const std::string e = dbus::error_name(status);
        CHECK(e == "org.caracara.Vehicle1.Error." + std::string(name));
        names.insert(e);
    }
    CHECK(names.size() == EnumNames<Status>::table.size());
}

TEST_CASE("error_reply: a reply now, empty or the named error with its message") {
    ServiceRig s;
    TestObject o(s);
    BusReply ok = call(s, "Ok");
    CHECK(ok.ok());
    uint8_t type = 0;
    REQUIRE(sd_bus_message_get_type(ok.reply.get(), &type) >= 0);
    CHECK(type == SD_BUS_MESSAGE_METHOD_RETURN);
    BusReply refused = call(s, "Refuse");
    CHECK(refused.error == "org.caracara.Vehicle1.Error.OutOfRange");
    CHECK(refused.message == "motor 9 is outside 0..7");
}

TEST_CASE("error_reply: reply_later answers when its completion is called, with its result") {
    ServiceRig s;
    TestObject o(s);
    CHECK(call_later(s, o, "Later", Result{}).ok());
    BusReply r = call_later(s, o, "Later", Result{Status::Killed, "the vehicle was killed during the turn"});
    CHECK(r.error == "org.caracara.Vehicle1.Error.Killed");
    CHECK(r.message == "the vehicle was killed during the turn");
}

TEST_CASE("error_reply: reply_filled_later carries the values; a failure is its error, a reply that cannot be built is Hardware") {
    ServiceRig s;
    TestObject o(s);
    BusReply r = call_later(s, o, "Filled", Result{});
    REQUIRE(r.ok());
    uint32_t value = 0;
    REQUIRE(sd_bus_message_read(r.reply.get(), "u", &value) >= 0);
    CHECK(value == 42);

    o.held.filled = false;
    r = call_later(s, o, "Filled", Result{Status::Busy, "a bus scan is running"});
    CHECK(r.error == "org.caracara.Vehicle1.Error.Busy");
    CHECK(r.message == "a bus scan is running");
    CHECK_FALSE(o.held.filled); // a failure has no values to build

    o.held.fill_result = -EINVAL;
    r = call_later(s, o, "Filled", Result{});
    CHECK(r.error == "org.caracara.Vehicle1.Error.Hardware");
    CHECK(r.message == "cannot build the reply");
}
