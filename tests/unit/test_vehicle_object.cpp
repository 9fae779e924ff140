// dbus/VehicleObject (/org/caracara/Vehicle1) on a private dbus-daemon, serving the daemon's
// objects on the fakes of the device seam (ServiceRig): what each property reads, each method's
// reply and its named error (org.caracara.Vehicle1.Error.<Status>, the one error map of
// dbus/error_reply), and that a refused call changes nothing, on the bus and on the fake wire.
#include "core/budget.hpp"
#include "core/packet.hpp"
#include "core/status.hpp"
#include "tests/catch.hpp"
#include "tests/unit/fakes/service_rig.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

using namespace caracara;
using namespace caracara::test;
using dbus::kRootPath;
using dbus::kVehicleIface;

namespace {

// The contract's name (the XML), written out: not the map under test.
std::string error(Status s) { return "org.caracara.Vehicle1.Error." + std::string(status_name(s)); }

BusReply set_thrust(ServiceRig& s, const std::vector<int32_t>& values) { return s.set_thrust(values); }

std::string text(ServiceRig& s, const char* property) { return s.text(kRootPath, kVehicleIface, property); }
std::vector<int32_t> motor_values(ServiceRig& s) { return s.ints(kRootPath, kVehicleIface, "MotorValues"); }

bool each_ordered(ServiceRig& s, const std::vector<int32_t>& values) { return s.each_ordered(values); }

// Any order on the wire that is neither `a`'s nor `b`'s value for its thruster.
bool other_order(ServiceRig& s, const std::vector<int32_t>& a, const std::vector<int32_t>& b) {
    return find(s.rig().wire().events(), [&](const WireEvent& e) {
               return e.kind == WireEvent::Kind::Order && e.value != on_wire(a[e.thruster]) &&
                      e.value != on_wire(b[e.thruster]);
           }) >= 0;
}

// Ready, with kThrust commanded by the test's client and on the wire.
void drive(ServiceRig& s) {
    s.rig().run_until_ready();
    REQUIRE(set_thrust(s, kThrust).ok());
    REQUIRE(s.rig().run_until([&] { return each_ordered(s, kThrust); }));
}

} // namespace

TEST_CASE("VehicleObject: the properties read the vehicle, the settings and the loop") {
    ServiceRig s;
    s.rig().run_until_ready();
    const DaemonConfig& c = s.rig().config();
    CHECK(text(s, "State") == "ready");
    CHECK(text(s, "KillSource").empty()); // a source only while killed
    CHECK(motor_values(s) == kZeros);
    CHECK(s.ints(kRootPath, kVehicleIface, "RequestedValues") == kZeros);
    CHECK(text(s, "Controller").empty());
    CHECK(text(s, "BudgetPolicy") == std::string(policy_name(c.control.budget_policy)));
    CHECK(text(s, "Profile") == c.control.profile);
    CHECK(s.basic<double>(kRootPath, kVehicleIface, "ProfileFactor", 'd') == 1.0);
    CHECK(s.basic<uint32_t>(kRootPath, kVehicleIface, "CommandTimeoutMs", 'u') == c.control.command_timeout_ms);
    CHECK(s.basic<uint32_t>(kRootPath, kVehicleIface, "ArmingDelayMs", 'u') == c.control.arming_delay_ms);
    CHECK(s.basic<double>(kRootPath, kVehicleIface, "LoopRateHz", 'd') == double(c.control.loop_rate_hz));
    CHECK(s.basic<int32_t>(kRootPath, kVehicleIface, "MotorTestLimit", 'i') == c.commissioning.motor_test_limit);
    CHECK(s.basic<uint64_t>(kRootPath, kVehicleIface, "SurfacingUntil", 't') == 0);
    CHECK(s.basic<uint64_t>(kRootPath, kVehicleIface, "PilotLostKillAt", 't') == 0);
    BusReply fs = s.get(kRootPath, kVehicleIface, "Failsafes", "a(ssi)");
    CHECK(sd_bus_message_enter_container(fs.reply.get(), 'a', "(ssi)") >= 0);
    CHECK(sd_bus_message_at_end(fs.reply.get(), 0) > 0); // none active
    // Cycles is the loop's count, read when asked: it moves between two reads.
    const uint64_t cycles = s.basic<uint64_t>(kRootPath, kVehicleIface, "Cycles", 't');
    CHECK(cycles == s.rig().loop().cycles());
    s.rig().run_until([&] { return s.rig().loop().cycles() > cycles; });
    CHECK(s.basic<uint64_t>(kRootPath, kVehicleIface, "Cycles", 't') > cycles);
}

TEST_CASE("VehicleObject: SetThrust is replied to, the caller becomes the controller, the values reach the wire") {
    ServiceRig s;
    s.rig().run_until_ready();
    s.rig().wire().clear();
    BusReply r = set_thrust(s, kThrust);
    REQUIRE(r.ok());
    CHECK(motor_values(s) == kThrust);
    CHECK(s.ints(kRootPath, kVehicleIface, "RequestedValues") == kThrust);
    CHECK(text(s, "Controller") == s.client_name());
    CHECK(s.rig().run_until([&] { return each_ordered(s, kThrust); }));
}

TEST_CASE("VehicleObject: SetThrust refused for its length, its range or its signature changes nothing") {
    ServiceRig s;
    drive(s);
    s.rig().wire().clear();
    std::vector<int32_t> seven(kThrust.begin(), kThrust.end() - 1);
    BusReply r = set_thrust(s, seven);
    CHECK(r.error == error(Status::InvalidLength));
    CHECK(r.message.find("exactly 8") != std::string::npos);
    std::vector<int32_t> nine = kThrust;
    nine.push_back(0);
    CHECK(set_thrust(s, nine).error == error(Status::InvalidLength));
    std::vector<int32_t> far = kThrust;
    far[3] = kMotorMax + 1;
    r = set_thrust(s, far);
    CHECK(r.error == error(Status::OutOfRange));
    CHECK(r.message.find("motor 3") != std::string::npos);
    far[3] = -kMotorMax - 1;
    CHECK(set_thrust(s, far).error == error(Status::OutOfRange));
    // Malformed arguments are sd-bus's to refuse, before the vehicle sees them.
    CHECK(s.call(kRootPath, kVehicleIface, "SetThrust", "s", "1000").error == "org.freedesktop.DBus.Error.InvalidArgs");
    CHECK(motor_values(s) == kThrust);
    CHECK(s.ints(kRootPath, kVehicleIface, "RequestedValues") == kThrust);
    // The loop keeps ordering the accepted values, and nothing else.
    s.rig().run_for(100);
    CHECK(each_ordered(s, kThrust));
    CHECK_FALSE(other_order(s, kThrust, kThrust));
}

TEST_CASE("VehicleObject: Kill, then commands refused as Killed until ClearKill; ClearKill twice is NotKilled") {
    ServiceRig s;
    drive(s);
    REQUIRE(s.call(kRootPath, kVehicleIface, "Kill", "").ok());
    CHECK(text(s, "State") == "killed");
    CHECK(text(s, "KillSource") == "dbus");
    CHECK(motor_values(s) == kZeros);
    CHECK(each_ordered(s, kZeros)); // Kill is replied to after the zeros
    s.rig().wire().clear();
    CHECK(set_thrust(s, kThrust).error == error(Status::Killed));
    CHECK(s.call(kRootPath, kVehicleIface, "SetMotion", "dddddd", 0.5, 0.0, 0.0, 0.0, 0.0, 0.0).error ==
          error(Status::Killed));
    CHECK(motor_values(s) == kZeros);
    s.rig().run_for(50);
    CHECK_FALSE(other_order(s, kZeros, kZeros));
    REQUIRE(s.call(kRootPath, kVehicleIface, "ClearKill", "").ok());
    CHECK(text(s, "State") == "ready");
    CHECK(text(s, "KillSource").empty()); // a source only while killed
    CHECK(s.call(kRootPath, kVehicleIface, "ClearKill", "").error == error(Status::NotKilled));
    CHECK(text(s, "State") == "ready");
}

TEST_CASE("VehicleObject: SetMotion mixes into motor values; a non-finite or out-of-range axis changes nothing") {
    ServiceRig s;
    s.rig().run_until_ready();
    REQUIRE(s.call(kRootPath, kVehicleIface, "SetMotion", "dddddd", 0.5, 0.0, 0.0, 0.0, 0.0, 0.0).ok());
    const std::vector<int32_t> mixed = motor_values(s);
    CHECK(mixed != kZeros);
    CHECK(text(s, "Controller") == s.client_name());
    CHECK(s.rig().run_until([&] { return each_ordered(s, mixed); }));
    const double nan = std::numeric_limits<double>::quiet_NaN();
    BusReply r = s.call(kRootPath, kVehicleIface, "SetMotion", "dddddd", 0.0, nan, 0.0, 0.0, 0.0, 0.0);
    CHECK(r.error == error(Status::InvalidValue));
    CHECK(r.message.find("finite") != std::string::npos);
    CHECK(s.call(kRootPath, kVehicleIface, "SetMotion", "dddddd", 0.0, 0.0, 1.5, 0.0, 0.0, 0.0).error ==
          error(Status::OutOfRange));
    CHECK(motor_values(s) == mixed);
}

TEST_CASE("VehicleObject: SetProfile, PowerOff, MotorTest, SetLeds, ClearKillOverride: each refusal named, nothing moved") {
    ServiceRig s;
    drive(s);
    s.rig().wire().clear();
    BusReply r = s.call(kRootPath, kVehicleIface, "SetProfile", "s", "vacuum");
    CHECK(r.error == error(Status::UnknownProfile));
    CHECK(text(s, "Profile") == "water");
    REQUIRE(s.call(kRootPath, kVehicleIface, "SetProfile", "s", "water").ok());

    CHECK(s.call(kRootPath, kVehicleIface, "PowerOff", "s", "yes").error == error(Status::ConfirmationRequired));
    CHECK(text(s, "State") == "ready");

    const int32_t limit = s.rig().config().commissioning.motor_test_limit;
    CHECK(s.call(kRootPath, kVehicleIface, "MotorTest", "ii", int32_t(kMotorCount), 100).error == error(Status::OutOfRange));
    CHECK(s.call(kRootPath, kVehicleIface, "MotorTest", "ii", -1, 100).error == error(Status::OutOfRange));
    CHECK(s.call(kRootPath, kVehicleIface, "MotorTest", "ii", 0, limit + 1).error == error(Status::OutOfRange));
    BusReply mt = s.get(kRootPath, kVehicleIface, "MotorTest", "(ii)");
    int32_t thruster = 0, value = 0;
    REQUIRE(sd_bus_message_read(mt.reply.get(), "(ii)", &thruster, &value) >= 0);
    CHECK(thruster == -1);
    CHECK(value == 0);

    // The Teensy is not fitted on the fakes: the LEDs cannot be set, and read as they were.
    CHECK(s.call(kRootPath, kVehicleIface, "SetLeds", "yyy", 10, 20, 30).error == error(Status::LinkError));
    BusReply leds = s.get(kRootPath, kVehicleIface, "Leds", "(yyy)");
    uint8_t red = 1, green = 1, blue = 1;
    REQUIRE(sd_bus_message_read(leds.reply.get(), "(yyy)", &red, &green, &blue) >= 0);
    CHECK(std::tuple{red, green, blue} == std::tuple{0, 0, 0});

    CHECK(s.call(kRootPath, kVehicleIface, "ClearKillOverride", "s", "no-such-condition").error ==
          error(Status::InvalidValue));

    // None of them touched the vehicle: the same controller, values and wire.
    CHECK(text(s, "Controller") == s.client_name());
    CHECK(motor_values(s) == kThrust);
    s.rig().run_for(50);
    CHECK_FALSE(other_order(s, kThrust, kThrust));
    CHECK(find(s.rig().wire().events(), [](const WireEvent& e) { return e.kind == WireEvent::Kind::PowerOff; }) < 0);
}

TEST_CASE("VehicleObject: a MotorTest in range drives its one thruster and shows in MotorTest") {
    ServiceRig s;
    s.rig().run_until_ready();
    REQUIRE(s.call(kRootPath, kVehicleIface, "MotorTest", "ii", 2, 800).ok());
    BusReply mt = s.get(kRootPath, kVehicleIface, "MotorTest", "(ii)");
    int32_t thruster = 0, value = 0;
    REQUIRE(sd_bus_message_read(mt.reply.get(), "(ii)", &thruster, &value) >= 0);
    CHECK(thruster == 2);
    CHECK(value == 800);
    std::vector<int32_t> one = kZeros;
    one[2] = 800;
    CHECK(s.rig().run_until([&] { return each_ordered(s, one); }));
}

TEST_CASE("VehicleObject: Preflight and ScanBus answer later with their tables; DetectDirections names its error") {
    ServiceRig s;
    s.rig().run_until_ready();
    BusReply p = s.call(kRootPath, kVehicleIface, "Preflight", "");
    REQUIRE(p.ok());
    sd_bus_message* m = p.reply.get();
    REQUIRE(sd_bus_message_enter_container(m, 'a', "(sbss)") >= 0);
    std::size_t rows = 0;
    const char *name = nullptr, *observed = nullptr, *advice = nullptr;
    int go = 0;
    bool recorder_seen = false;
    while (sd_bus_message_read(m, "(sbss)", &name, &go, &observed, &advice) > 0) {
        ++rows;
        if (std::string(name) == "recorder") {
            recorder_seen = true;
            CHECK_FALSE(go); // the rig runs without a recorder
            CHECK(std::string(observed) == "disabled");
        }
    }
    CHECK(rows == s.rig().daemon().preflight().rows().size());
    CHECK(rows == kMotorCount + 8);
    CHECK(recorder_seen);

    // Direction detection measures the Teensy's orientation: not fitted, it cannot run.
    CHECK(s.call(kRootPath, kVehicleIface, "DetectDirections", "").error == error(Status::LinkError));
    CHECK(text(s, "Controller").empty());
    // The scan probes the bus between the orders: only a killed vehicle's.
    CHECK(s.call(kRootPath, kVehicleIface, "ScanBus", "").error == error(Status::NotKilled));
    CHECK(text(s, "State") == "ready");
    REQUIRE(s.call(kRootPath, kVehicleIface, "Kill", "").ok());
    BusReply scan = s.call(kRootPath, kVehicleIface, "ScanBus", "");
    INFO(scan.error << ": " << scan.message);
    REQUIRE(scan.ok());
    m = scan.reply.get();
    REQUIRE(sd_bus_message_enter_container(m, 'a', "(qiysyi)") >= 0);
    std::size_t devices = 0;
    uint16_t mux = 0;
    int32_t channel = 0, configured = 0;
    uint8_t mt = 0, revision = 0;
    const char* variant = nullptr;
    while (sd_bus_message_read(m, "(qiysyi)", &mux, &channel, &mt, &variant, &revision, &configured) > 0)
        ++devices;
    CHECK(devices == s.rig().daemon().bus_scan().report().devices.size());
    REQUIRE(sd_bus_message_exit_container(m) >= 0);
    REQUIRE(sd_bus_message_enter_container(m, 'a', "(ss)") >= 0);
    std::size_t verdicts = 0;
    const char *verdict = nullptr, *why = nullptr;
    while (sd_bus_message_read(m, "(ss)", &verdict, &why) > 0)
        ++verdicts;
    CHECK(verdicts == s.rig().config().thrusters.size());

}

TEST_CASE("VehicleObject: a command's change is announced in PropertiesChanged") {
    ServiceRig s;
    s.rig().run_until_ready();
    std::vector<int32_t> announced;
    s.watch_property(kRootPath, "MotorValues", "ai", [&](sd_bus_message* m) {
        const void* p = nullptr;
        size_t n = 0;
        sd_bus_message_read_array(m, 'i', &p, &n);
        const auto* v = static_cast<const int32_t*>(p);
        announced.assign(v, v + n / sizeof(int32_t));
    });
    REQUIRE(set_thrust(s, kThrust).ok());
    CHECK(s.rig().run_until([&] { return announced == kThrust; }));
}

TEST_CASE("VehicleObject: a failsafe that kills: the Failsafe signal, Failsafes, ClearKill refused by its name until it clears") {
    ServiceRig s;
    drive(s);
    struct Seen {
        std::string condition, action;
        int32_t thruster = 0;
    } seen;
    auto on_failsafe = [](sd_bus_message* m, void* userdata, sd_bus_error*) {
        auto* out = static_cast<Seen*>(userdata);
        const char *condition = nullptr, *action = nullptr;
        if (sd_bus_message_read(m, "ssi", &condition, &action, &out->thruster) >= 0) {
            out->condition = condition;
            out->action = action;
        }
        return 0;
    };
    sd_bus_slot* slot = nullptr;
    REQUIRE(sd_bus_match_signal(s.client(), &slot, dbus::kBusName, kRootPath, kVehicleIface, "Failsafe", on_failsafe,
                                &seen) >= 0);
    dbus::SlotPtr held(slot);
    s.rig().daemon().failsafes().push(FailsafeCondition::TeensyLinkLost, true, "test: the Teensy stopped answering");
    REQUIRE(s.rig().run_until([&] { return !seen.condition.empty(); }));
    CHECK(seen.condition == "teensy-link-lost");
    CHECK(seen.action == std::string(action_name(FailsafeAction::Kill)));
    CHECK(seen.thruster == -1);
    CHECK(text(s, "State") == "killed");
    CHECK(motor_values(s) == kZeros);
    BusReply fs = s.get(kRootPath, kVehicleIface, "Failsafes", "a(ssi)");
    REQUIRE(sd_bus_message_enter_container(fs.reply.get(), 'a', "(ssi)") >= 0);
    const char *condition = nullptr, *action = nullptr;
    int32_t thruster = 0;
    REQUIRE(sd_bus_message_read(fs.reply.get(), "(ssi)", &condition, &action, &thruster) > 0);
    CHECK(std::string(condition) == "teensy-link-lost");
    CHECK(sd_bus_message_at_end(fs.reply.get(), 0) > 0);

    BusReply r = s.call(kRootPath, kVehicleIface, "ClearKill", "");
    CHECK(r.error == error(Status::FailsafeActive));
    CHECK(r.message.find("teensy-link-lost") != std::string::npos);
    // Fixed at kill: no override.
    CHECK(s.call(kRootPath, kVehicleIface, "ClearKillOverride", "s", "teensy-link-lost").error ==
          error(Status::FailsafeActive));
    CHECK(text(s, "State") == "killed");

    s.rig().daemon().failsafes().push(FailsafeCondition::TeensyLinkLost, false, "test: the Teensy answers again");
    s.rig().run_for(50);
    REQUIRE(s.call(kRootPath, kVehicleIface, "ClearKill", "").ok());
    CHECK(text(s, "State") == "ready");
}

TEST_CASE("VehicleObject: ApplyPacket drives, kills, and refuses a malformed packet without moving anything") {
    ServiceRig s;
    s.rig().run_until_ready();
    const auto apply = [&](const std::vector<int32_t>& words) {
        return s.call_with(kRootPath, kVehicleIface, "ApplyPacket", [&](sd_bus_message* m) {
            return sd_bus_message_append_array(m, 'i', words.data(), words.size() * sizeof(int32_t));
        });
    };
    std::vector<int32_t> packet(kPacketWords, 0);
    std::copy(kThrust.begin(), kThrust.end(), packet.begin());
    REQUIRE(apply(packet).ok());
    CHECK(motor_values(s) == kThrust);
    CHECK(text(s, "Controller") == s.client_name());
    REQUIRE(s.rig().run_until([&] { return each_ordered(s, kThrust); }));

    s.rig().wire().clear();
    std::vector<int32_t> other = packet;
    other[0] = 2500;
    std::vector<int32_t> short_packet(other.begin(), other.end() - 1);
    BusReply r = apply(short_packet);
    CHECK(r.error == error(Status::InvalidLength));
    std::vector<int32_t> bad_power = other;
    bad_power[kPacketPowerOff] = 7;
    r = apply(bad_power);
    INFO(r.error << ": " << r.message);
    CHECK(r.error == error(Status::InvalidValue));
    std::vector<int32_t> far = other;
    far[1] = kMotorMax + 1;
    CHECK(apply(far).error == error(Status::OutOfRange));
    CHECK(motor_values(s) == kThrust);
    s.rig().run_for(50);
    CHECK_FALSE(other_order(s, kThrust, kThrust));
    CHECK(text(s, "State") == "ready");

    // A packet that kills: replied to after the zeros, killed by the packet.
    std::vector<int32_t> kill = packet;
    kill[kPacketKill] = 1;
    REQUIRE(apply(kill).ok());
    CHECK(each_ordered(s, kZeros));
    CHECK(text(s, "State") == "killed");
    CHECK(text(s, "KillSource") == "packet");
}
