// dbus/BusInputProbe on a private dbus-daemon (ServiceRig's bus): the control loop's question
// "is D-Bus input waiting?" answered for a connection: a message read off the socket but not
// yet dispatched is waiting; once dispatched, nothing is; its fd is the connection's.
#include "dbus/bus_input_probe.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

using namespace caracara;
using namespace caracara::test;

namespace {
// Dispatches everything the connection has read (the loop is not run here).
void dispatch_all(sd_bus* bus) {
    while (sd_bus_process(bus, nullptr) > 0) {
    }
}
} // namespace

TEST_CASE("BusInputProbe: a message read but not dispatched is waiting input; dispatched, none") {
    ServiceRig s;
    dbus::BusPtr reader = s.connect("reader");
    dbus::BusPtr sender = s.connect("sender");
    dbus::BusInputProbe probe(reader.get());
    CHECK(probe.fd() == sd_bus_get_fd(reader.get()));
    sd_bus_slot* slot = nullptr;
    int seen = 0;
    REQUIRE(sd_bus_match_signal(reader.get(), &slot, nullptr, "/test", "org.caracara.ProbeTest", "Ping",
                                [](sd_bus_message*, void* u, sd_bus_error*) {
                                    ++*static_cast<int*>(u);
                                    return 0;
                                },
                                &seen) >= 0);
    dbus::SlotPtr held(slot);
    dispatch_all(reader.get()); // what the bus sent at connect (NameAcquired)
    CHECK_FALSE(probe.queued());
    REQUIRE(sd_bus_emit_signal(sender.get(), "/test", "org.caracara.ProbeTest", "Ping", "") >= 0);
    REQUIRE(sd_bus_flush(sender.get()) >= 0);
    // A synchronous call reads what arrives before its reply and queues it, undispatched: the
    // signal, once the bus has routed it. Each time input waits, it is dispatched, and then
    // none waits.
    bool waited = false;
    for (int i = 0; i < 200 && seen == 0; ++i) {
        sd_bus_message* reply = nullptr;
        REQUIRE(sd_bus_call_method(reader.get(), "org.freedesktop.DBus", "/org/freedesktop/DBus",
                                   "org.freedesktop.DBus", "GetId", nullptr, &reply, "") >= 0);
        sd_bus_message_unref(reply);
        if (probe.queued()) {
            waited = true;
            dispatch_all(reader.get());
            CHECK_FALSE(probe.queued());
        }
    }
    CHECK(seen == 1);
    CHECK(waited);
}
