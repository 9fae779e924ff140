// The SeaBotix driver through the real i2c-dev marshalling code against caracara-sim,
// checked on the simulator's side of the wire.
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/protocol/seabotix.hpp"
#include "drivers/platform/linux/linux_device_io.hpp"
#include "drivers/platform/sim/sim_device_io.hpp"
#include "tests/integration/sim_fixture.hpp"
#include "drivers/devices/thruster_driver.hpp"
#include "drivers/devices/thruster_probe.hpp"

#include "tests/catch.hpp"
#include <memory>
#include <stdexcept>
#include <thread>

using namespace caracara;
using caracara::test::SimFixture;

namespace {
// Default vehicle: eight SeaBotix controllers at these MT bytes (sim and daemon agree).
constexpr uint8_t kDefaultMt[8] = {0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62};

// Independent of the codec: the IDS arithmetic written out.
uint8_t speed_byte(int v) {
    const int steps = (std::abs(v) * 102 + 4425) / 8850; // round half up of |v|*102/8850
    if (steps == 0)
        return 0x80;
    return static_cast<uint8_t>(v > 0 ? 0x80 + steps : 0x7F - steps);
}

struct Bench {
    SimFixture& f;
    SimDeviceIo io;
    std::unique_ptr<I2cDev> bus;
    MuxTracker mux;
    std::vector<std::unique_ptr<ThrusterDriver>> thrusters;
    explicit Bench(SimFixture& fx, const std::vector<ThrusterConfig>& cfgs) : f(fx) {
        REQUIRE(io.connect(f.socket()) == 0);
        bus = std::make_unique<I2cDev>(io, "/dev/i2c-1");
        REQUIRE(bus->open() == 0);
        for (const auto& c : cfgs)
            thrusters.push_back(std::make_unique<ThrusterDriver>(*bus, mux, c));
    }
};

// Two thrusters at MT 0x52 behind PCA9544A muxes: (mux, channel) each.
std::string two_muxed(uint16_t mux_a, uint8_t ch_a, uint16_t mux_b, uint8_t ch_b) {
    auto one = [](uint16_t mux, uint8_t ch) {
        return "[[thruster]]\naddress = 0x52\nmux_address = " + std::to_string(mux) + "\nmux_channel = " +
               std::to_string(ch) + "\n";
    };
    return one(mux_a, ch_a) + one(mux_b, ch_b);
}

ThrusterConfig muxed(uint16_t mux, uint8_t ch) {
    ThrusterConfig c;
    c.mt = 0x52;
    c.mux = MuxRoute{mux, ch};
    return c;
}

std::vector<ThrusterConfig> default_configs() {
    std::vector<ThrusterConfig> v;
    for (uint8_t mt : kDefaultMt) {
        ThrusterConfig c;
        c.mt = mt;
        v.push_back(c);
    }
    return v;
}
} // namespace

TEST_CASE("a thruster driver refuses a configuration the rules refuse, before any transfer") {
    LinuxDeviceIo io;
    I2cDev bus(io, "/dev/null"); // never opened: the constructor refuses first
    MuxTracker mux;
    ThrusterConfig read_address;
    read_address.mt = 0x53; // odd: a read address byte
    CHECK_THROWS_AS(ThrusterDriver(bus, mux, read_address), std::invalid_argument);
}

TEST_CASE("all eight thrusters receive exactly the order bytes the IDS prescribes") {
    SimFixture f;
    Bench b(f, default_configs());
    const int values[8] = {8850, -8850, 0, 44, -43, 4200, -4200, 1};
    for (size_t i = 0; i < 8; ++i)
        REQUIRE(b.thrusters[i]->send_order(values[i]) == IoError::None);
    for (unsigned i = 0; i < 8; ++i) {
        const uint8_t speed = speed_byte(values[i]);
        const uint8_t csum = static_cast<uint8_t>(kDefaultMt[i] + speed + 100);
        INFO("thruster " << i << " value " << values[i]);
        CHECK(f.thruster_bytes(i, "LastOrder") == std::vector<uint8_t>{speed, 100, csum});
        CHECK(f.thruster_byte(i, "OrderedSpeed") == speed);
        CHECK(f.thruster_u64(i, "OrdersRejected") == 0);
        CHECK(b.thrusters[i]->online());
    }
    // One I2C_RDWR per thruster transaction, one write message each, in order.
    auto log = f.wire_log();
    REQUIRE(log.size() == 8);
    for (unsigned i = 0; i < 8; ++i) {
        CHECK(log[i].addr == kDefaultMt[i] >> 1);
        CHECK_FALSE(log[i].read);
        CHECK(log[i].data.size() == 3);
        if (i)
            CHECK(log[i].transaction != log[i - 1].transaction);
    }
}

TEST_CASE("status replies of both variants decode to the simulated thruster's state") {
    const std::string cfg = R"(
[[thruster]]
address = 0x52
variant = "seabotix"
[[thruster]]
address = 0x54
variant = "legacy"
)";
    SimFixture probe;
    SimFixture f({"--config", probe.write_file("vehicle.toml", cfg)});
    ThrusterConfig a;
    a.mt = 0x52;
    ThrusterConfig l;
    l.mt = 0x54;
    l.variant = Variant::Legacy;
    Bench b(f, {a, l});
    REQUIRE(b.thrusters[0]->send_order(8850) == IoError::None);
    REQUIRE(b.thrusters[1]->send_order(8850) == IoError::None);
    // The simulated motors ramp up to full speed and draw current.
    for (int i = 0; i < 500 && f.thruster_byte(0, "ActualSpeed") != 0xE6; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    REQUIRE(f.thruster_byte(0, "ActualSpeed") == 0xE6);
    REQUIRE(b.thrusters[0]->read_status() == IoError::None);
    REQUIRE(b.thrusters[1]->read_status() == IoError::None);
    const auto& s = *b.thrusters[0]->last_status();
    CHECK(s.variant == Variant::SeaBotix);
    CHECK(int(s.seabotix.speed) == 0xE6);
    CHECK(s.seabotix.speed > 0x80);
    REQUIRE(s.current_deciamps);
    CHECK(*s.current_deciamps > 0);
    const auto& ls = *b.thrusters[1]->last_status();
    CHECK(ls.variant == Variant::Legacy);
    CHECK(ls.legacy.software == LegacySoftware::AveoxBrushless);
    REQUIRE(ls.current_deciamps);
    CHECK(*ls.current_deciamps > 0);
    CHECK(f.thruster_u64(0, "StatusReads") == 1);

    SECTION("each fault bit the simulator raises is decoded by name") {
        for (const char* fault : {"overtemp", "stall", "hall", "ground-fault", "water-detect"}) {
            INFO(fault);
            REQUIRE(f.call(f.thruster_path(0), "org.caracara.Simulator1.Thruster", "SetFault", "sb", fault, 1) == "");
            REQUIRE(b.thrusters[0]->read_status() == IoError::None);
            CHECK(format_faults(b.thrusters[0]->last_status()->faults).find(fault) != std::string::npos);
            REQUIRE(f.call(f.thruster_path(0), "org.caracara.Simulator1.Thruster", "SetFault", "sb", fault, 0) == "");
        }
        // Ground fault latches until the controller is power-cycled (IDS 8.4.2 remark 3).
        REQUIRE(b.thrusters[0]->read_status() == IoError::None);
        CHECK(b.thrusters[0]->last_status()->faults.has(Fault::GroundFault));
        REQUIRE(f.call(f.thruster_path(0), "org.caracara.Simulator1.Thruster", "PowerCycle", "") == "");
        REQUIRE(b.thrusters[0]->read_status() == IoError::None);
        CHECK_FALSE(b.thrusters[0]->last_status()->faults.any());
    }
}

TEST_CASE("corrupted replies are discarded and counted, a NACKing thruster goes offline and comes back") {
    SimFixture f;
    Bench b(f, default_configs());
    ThrusterDriver& t = *b.thrusters[2];
    REQUIRE(t.read_status() == IoError::None);
    const auto good = *t.last_status();

    REQUIRE(f.call(f.thruster_path(2), "org.caracara.Simulator1.Thruster", "CorruptReplies", "us", 1u, "checksum") == "");
    CHECK(t.read_status() == IoError::BadReply);
    CHECK(t.counters().bad_checksum == 1);
    CHECK_FALSE(t.online());
    REQUIRE(f.call(f.thruster_path(2), "org.caracara.Simulator1.Thruster", "CorruptReplies", "us", 1u, "first-byte") == "");
    CHECK(t.read_status() == IoError::BadReply);
    CHECK(t.counters().bad_first_byte == 1);
    CHECK(t.last_status()->seabotix.status == good.seabotix.status); // the bad ones were not believed
    CHECK(t.read_status() == IoError::None);
    CHECK(t.online());

    REQUIRE(f.call(f.thruster_path(2), "org.caracara.Simulator1.Thruster", "SetNack", "b", 1) == "");
    CHECK(t.send_order(1000) == IoError::Nack);
    CHECK(t.read_status() == IoError::Nack);
    CHECK(t.counters().nacks == 2);
    CHECK_FALSE(t.online());
    // The others are unaffected: one missing thruster is not a dead bus.
    CHECK(b.thrusters[3]->send_order(1000) == IoError::None);
    REQUIRE(f.call(f.thruster_path(2), "org.caracara.Simulator1.Thruster", "SetNack", "b", 0) == "");
    CHECK(t.send_order(1000) == IoError::None);
    CHECK(t.online());
    CHECK(f.thruster_byte(2, "OrderedSpeed") == speed_byte(1000));
}

TEST_CASE("same-address thrusters behind a PCA9544A get their channel selected first") {
    SimFixture probe;
    SimFixture f({"--config", probe.write_file("vehicle.toml", two_muxed(0x70, 0, 0x70, 1))});
    Bench b(f, {muxed(0x70, 0), muxed(0x70, 1)});
    REQUIRE(b.thrusters[0]->send_order(2000) == IoError::None);
    REQUIRE(b.thrusters[1]->send_order(-2000) == IoError::None);
    REQUIRE(b.thrusters[0]->send_order(2000) == IoError::None);
    CHECK(f.thruster_byte(0, "OrderedSpeed") == speed_byte(2000));
    CHECK(f.thruster_byte(1, "OrderedSpeed") == speed_byte(-2000));
    CHECK(f.thruster_u64(0, "OrdersReceived") == 2);
    CHECK(f.thruster_u64(1, "OrdersReceived") == 1);
    // On the wire: select ch0 (0x04), order, select ch1 (0x05), order, select ch0, order.
    auto log = f.wire_log();
    REQUIRE(log.size() == 6);
    CHECK(log[0].addr == 0x70);
    CHECK(log[0].data == std::vector<uint8_t>{0x04});
    CHECK(log[1].addr == 0x29);
    CHECK(log[2].data == std::vector<uint8_t>{0x05});
    CHECK(log[4].data == std::vector<uint8_t>{0x04});
}

TEST_CASE("a bus scan's probe: the trunk alone with every channel off, then each channel") {
    SimFixture probe;
    SimFixture f({"--config", probe.write_file("vehicle.toml", two_muxed(0x70, 0, 0x71, 1))});
    Bench b(f, {muxed(0x70, 0), muxed(0x71, 1)});
    REQUIRE(b.thrusters[1]->send_order(0) == IoError::None); // 0x71 on channel 1
    CHECK(b.mux.enabled()->addr7 == 0x71);
    ProbeAnswer a;
    REQUIRE(b.mux.disable_all(*b.bus) == IoError::None);
    CHECK_FALSE(b.mux.enabled());
    CHECK(probe_thruster(*b.bus, 0x52, a) == IoError::Nack); // both behind a mux: nobody on the trunk
    REQUIRE(b.mux.select(*b.bus, 0x70, 0) == IoError::None);
    REQUIRE(probe_thruster(*b.bus, 0x52, a) == IoError::None);
    CHECK(a.variant == Variant::SeaBotix);
    CHECK(probe_thruster(*b.bus, 0x54, a) == IoError::Nack);
    CHECK(b.mux.enabled()->channel == 0);
}

TEST_CASE("reversed thrusters get the opposite direction on the wire") {
    SimFixture f;
    auto cfgs = default_configs();
    cfgs[5].reversed = true;
    Bench b(f, cfgs);
    REQUIRE(b.thrusters[5]->send_order(3000) == IoError::None);
    CHECK(f.thruster_byte(5, "OrderedSpeed") == speed_byte(-3000));
}

TEST_CASE("same-address thrusters behind two muxes: only one mux channel is ever enabled") {
    SimFixture probe;
    SimFixture f({"--config", probe.write_file("vehicle.toml", two_muxed(0x70, 0, 0x71, 0))});
    Bench b(f, {muxed(0x70, 0), muxed(0x71, 0)});
    REQUIRE(b.thrusters[0]->send_order(1500) == IoError::None);
    REQUIRE(b.thrusters[1]->send_order(-1500) == IoError::None);
    // Had both muxes been left on, both thrusters would have taken the second order.
    CHECK(f.thruster_byte(0, "OrderedSpeed") == speed_byte(1500));
    CHECK(f.thruster_byte(1, "OrderedSpeed") == speed_byte(-1500));
    CHECK(f.thruster_u64(0, "OrdersReceived") == 1);
    CHECK(f.thruster_u64(1, "OrdersReceived") == 1);
}

TEST_CASE("a NACK on one thruster does not disturb the mux state of the others") {
    SimFixture probe;
    SimFixture f({"--config", probe.write_file("vehicle.toml", two_muxed(0x70, 0, 0x70, 1))});
    Bench b(f, {muxed(0x70, 0), muxed(0x70, 1)});
    REQUIRE(f.call(f.thruster_path(0), "org.caracara.Simulator1.Thruster", "SetNack", "b", 1) == "");
    CHECK(b.thrusters[0]->send_order(1000) == IoError::Nack);
    CHECK(b.thrusters[0]->counters().nacks == 1);
    REQUIRE(b.thrusters[1]->send_order(2000) == IoError::None);
    CHECK(f.thruster_byte(1, "OrderedSpeed") == speed_byte(2000));
    REQUIRE(f.call(f.thruster_path(0), "org.caracara.Simulator1.Thruster", "SetNack", "b", 0) == "");
    // After the NACK the tracker re-selects channel 0 before talking to thruster 0 again.
    REQUIRE(b.thrusters[0]->send_order(1000) == IoError::None);
    CHECK(f.thruster_byte(0, "OrderedSpeed") == speed_byte(1000));
    CHECK(f.thruster_byte(1, "OrderedSpeed") == speed_byte(2000));
}
