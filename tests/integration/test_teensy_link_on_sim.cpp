// The Teensy link through the real spidev marshalling code against the simulated Teensy,
// checked through the simulator's inspection API.
#include "drivers/platform/sim/sim_device_io.hpp"
#include "tests/integration/sim_fixture.hpp"
#include "drivers/platform/spi_dev.hpp"
#include "drivers/protocol/teensy_codec.hpp"
#include "drivers/devices/teensy_link.hpp"

#include "tests/catch.hpp"
#include <cmath>
#include <ctime>
#include <memory>
#include <thread>

using namespace caracara;
using caracara::test::SimFixture;

namespace {
constexpr const char* kTeensyPath = "/org/caracara/Simulator1/teensy";
constexpr const char* kTeensyIface = "org.caracara.Simulator1.Teensy";

struct Link {
    SimDeviceIo io;
    std::unique_ptr<SpiDev> spi;
    std::unique_ptr<TeensyLink> link;
    Link(SimFixture& f, SpiConfig cfg = {}) {
        REQUIRE(io.connect(f.socket()) == 0);
        spi = std::make_unique<SpiDev>(io, "/dev/spidev0.0", cfg);
        REQUIRE(spi->open() == 0);
        link = std::make_unique<TeensyLink>(*spi);
    }
};

template <typename T>
T prop(SimFixture& f, const char* name, char type) {
    T v{};
    sd_bus_error e = SD_BUS_ERROR_NULL;
    REQUIRE(sd_bus_get_property_trivial(f.bus(), "org.caracara.Simulator1", kTeensyPath, kTeensyIface, name, &e, type, &v) >= 0);
    return v;
}

std::vector<uint8_t> bytes_prop(SimFixture& f, const char* name, const char* sig) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* m = nullptr;
    REQUIRE(sd_bus_get_property(f.bus(), "org.caracara.Simulator1", kTeensyPath, kTeensyIface, name, &e, &m, sig) >= 0);
    caracara::dbus::MessagePtr guard(m);
    std::vector<uint8_t> out;
    if (std::string(sig) == "(yyy)") {
        uint8_t r = 0, g = 0, b = 0;
        REQUIRE(sd_bus_message_read(m, "(yyy)", &r, &g, &b) >= 0);
        out = {r, g, b};
    } else {
        const void* p = nullptr;
        size_t n = 0;
        REQUIRE(sd_bus_message_read_array(m, 'y', &p, &n) >= 0);
        out.assign(static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
    }
    return out;
}

std::array<double, 3> orientation(SimFixture& f) {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* m = nullptr;
    REQUIRE(sd_bus_get_property(f.bus(), "org.caracara.Simulator1", kTeensyPath, kTeensyIface, "Orientation", &e, &m, "(ddd)") >= 0);
    caracara::dbus::MessagePtr guard(m);
    std::array<double, 3> o{};
    REQUIRE(sd_bus_message_read(m, "(ddd)", &o[0], &o[1], &o[2]) >= 0);
    return o;
}

uint64_t now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
}
} // namespace

TEST_CASE("every command reaches the simulated Teensy through spidev, full duplex and per-byte") {
    SimFixture f;
    for (uint16_t delay : {uint16_t{0}, uint16_t{5}}) {
        INFO("per-byte delay " << delay);
        Link l(f, SpiConfig{500000, delay});
        REQUIRE(l.link->set_leds(10, 20, 30) == teensy::TeensyError::None);
        CHECK(bytes_prop(f, "Leds", "(yyy)") == std::vector<uint8_t>{10, 20, 30});
        REQUIRE(l.link->servo(2, 135) == teensy::TeensyError::None);
        CHECK(bytes_prop(f, "Servos", "ay")[2] == 135);
        REQUIRE(f.call(kTeensyPath, kTeensyIface, "SetDistance", "yq", uint8_t{1}, uint16_t{1234}) == "");
        auto d = l.link->get_distance(1);
        REQUIRE(d.ok());
        CHECK(d.value == 1234);
        auto yaw = l.link->get_orientation(0);
        REQUIRE(yaw.ok());
        CHECK(std::fabs(yaw.value - orientation(f)[0]) < 1e-3);
        REQUIRE(l.link->stop(77) == teensy::TeensyError::None);
        CHECK(prop<uint8_t>(f, "StopDuty", 'y') == 77);
        REQUIRE(l.link->set_speed(100, -20) == teensy::TeensyError::None);
    }
    // The simulator saw the frames bytes as sent: the last Set Speed is [02 64 EC 00].
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* reply = nullptr;
    REQUIRE(sd_bus_call_method(f.bus(), "org.caracara.Simulator1", kTeensyPath, kTeensyIface, "GetFrameLog", &e, &reply, "") >= 0);
    caracara::dbus::MessagePtr guard(reply);
    REQUIRE(sd_bus_message_enter_container(reply, 'a', "(tttysayay)") > 0);
    std::vector<uint8_t> last_mosi;
    std::string last_outcome;
    while (sd_bus_message_enter_container(reply, 'r', "tttysayay") > 0) {
        uint64_t seq, t0, t1;
        uint8_t cmd;
        const char* outcome;
        sd_bus_message_read(reply, "tttys", &seq, &t0, &t1, &cmd, &outcome);
        const void* p;
        size_t n;
        sd_bus_message_read_array(reply, 'y', &p, &n);
        last_mosi.assign(static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
        sd_bus_message_read_array(reply, 'y', &p, &n);
        last_outcome = outcome;
        sd_bus_message_exit_container(reply);
    }
    CHECK(last_mosi == std::vector<uint8_t>{0x02, 0x64, 0xEC, 0x00});
    CHECK(last_outcome == "ok");
}

TEST_CASE("busy answers are resent after the delay, link faults are counted") {
    SimFixture f;
    Link l(f);
    REQUIRE(f.call(kTeensyPath, kTeensyIface, "InjectFault", "su", "busy", 3u) == "");
    REQUIRE(l.link->set_leds(1, 2, 3) == teensy::TeensyError::None);
    CHECK(l.link->counters().busy_retries == 3);
    CHECK(bytes_prop(f, "Leds", "(yyy)") == std::vector<uint8_t>{1, 2, 3});

    // More busy frames than retries: a named error, and the Teensy never acted.
    REQUIRE(f.call(kTeensyPath, kTeensyIface, "InjectFault", "su", "busy", 50u) == "");
    CHECK(l.link->set_leds(9, 9, 9) == teensy::TeensyError::BusyExhausted);
    CHECK(bytes_prop(f, "Leds", "(yyy)") == std::vector<uint8_t>{1, 2, 3});
    REQUIRE(f.call(kTeensyPath, kTeensyIface, "ClearFaults", "") == "");

    // No answer at all (MISO stuck low): a link error, counted; the link recovers after.
    REQUIRE(f.call(kTeensyPath, kTeensyIface, "InjectFault", "su", "no-answer", 2u) == "");
    CHECK(l.link->get_orientation(1).error == teensy::TeensyError::LinkError);
    CHECK(l.link->counters().link_errors == 2); // the first try and its single retry
    CHECK(l.link->get_orientation(1).ok());

    // A garbage ack on a relative Turn is not resent (the turn may have happened).
    REQUIRE(f.call(kTeensyPath, kTeensyIface, "InjectFault", "su", "garbage-ack", 1u) == "");
    CHECK(l.link->turn(0.1) == teensy::TeensyError::LinkError);
    uint64_t received = 0, executed = 0;
    sd_bus_error e = SD_BUS_ERROR_NULL;
    sd_bus_message* reply = nullptr;
    REQUIRE(sd_bus_call_method(f.bus(), "org.caracara.Simulator1", kTeensyPath, kTeensyIface, "CommandCount", &e, &reply, "y", uint8_t{0x03}) >= 0);
    sd_bus_message_read(reply, "tt", &received, &executed);
    sd_bus_message_unref(reply);
    CHECK(received == 1);
}

TEST_CASE("turn handshake: poll Confirm until finished, then acknowledge") {
    SimFixture f;
    Link l(f);
    const uint64_t acks_before = prop<uint64_t>(f, "Acknowledgements", 't');
    REQUIRE(l.link->turn(0.3) == teensy::TeensyError::None); // about 0.3 s at 1 rad/s
    CHECK(std::fabs(prop<double>(f, "LastTurn", 'd') - 0.3) < 1e-6);
    teensy::ConfirmHandshake hs(teensy::ConfirmHandshakeConfig{5'000'000, 10'000'000'000ull, 3});
    hs.start(now_ns());
    bool done = false;
    for (int guard = 0; guard < 10000 && !done; ++guard) {
        auto step = l.link->advance(hs); // sends every frame the handshake asks for
        switch (step.action) {
        case teensy::ConfirmHandshake::Action::Wait:
            std::this_thread::sleep_for(std::chrono::nanoseconds(step.at_ns > now_ns() ? step.at_ns - now_ns() : 0));
            break;
        case teensy::ConfirmHandshake::Action::Done: done = true; break;
        default: FAIL("handshake failed: " << teensy::teensy_error_name(step.error));
        }
    }
    const unsigned polls = hs.polls();
    CHECK(done);
    CHECK(polls > 2); // the task took time: several "not yet" answers first
    CHECK(prop<uint64_t>(f, "Acknowledgements", 't') == acks_before + 1);
    std::string task;
    sd_bus_error e = SD_BUS_ERROR_NULL;
    char* s = nullptr;
    REQUIRE(sd_bus_get_property_string(f.bus(), "org.caracara.Simulator1", kTeensyPath, kTeensyIface, "Task", &e, &s) >= 0);
    task = s;
    free(s);
    CHECK(task == "idle");
}

TEST_CASE("invalid inputs are refused before anything reaches the Teensy") {
    SimFixture f;
    Link l(f);
    const uint64_t frames = prop<uint64_t>(f, "Frames", 't');
    CHECK(l.link->servo(9, 90) == teensy::TeensyError::ServoIdOutOfRange);
    CHECK(l.link->servo(0, 181) == teensy::TeensyError::ServoAngleOutOfRange);
    CHECK(l.link->get_distance(7).error == teensy::TeensyError::SensorIdOutOfRange);
    CHECK(l.link->get_orientation(3).error == teensy::TeensyError::AxisOutOfRange);
    CHECK(l.link->turn(std::nan("")) == teensy::TeensyError::AngleNotFinite);
    CHECK(l.link->turn_to(INFINITY) == teensy::TeensyError::AngleNotFinite);
    CHECK(l.link->set_speed(128, 0) == teensy::TeensyError::SpeedOutOfRange);
    CHECK(l.link->set_leds(256, 0, 0) == teensy::TeensyError::LedValueOutOfRange);
    CHECK(prop<uint64_t>(f, "Frames", 't') == frames);
}

TEST_CASE("spidev is set up as mode 0, 8 bits at the configured speed; per-byte mode splits the frame") {
    SimFixture f;
    {
        Link l(f, SpiConfig{1000000, 0});
        CHECK(prop<uint8_t>(f, "SpiMode", 'y') == 0);
        CHECK(prop<uint8_t>(f, "SpiBitsPerWord", 'y') == 8);
        CHECK(prop<uint32_t>(f, "SpiMaxSpeedHz", 'u') == 1000000);
        REQUIRE(l.link->set_leds(4, 5, 6) == teensy::TeensyError::None);
        // One full-duplex spi_ioc_transfer carrying the whole frame.
        CHECK(prop<uint32_t>(f, "SpiLastTransfers", 'u') == 1);
        CHECK(prop<uint16_t>(f, "SpiLastDelayUsecs", 'q') == 0);
    }
    {
        Link l(f, SpiConfig{500000, 25});
        REQUIRE(l.link->set_leds(7, 8, 9) == teensy::TeensyError::None);
        // Set LEDs is [09 r g b ack]: five 1-byte transfers, each followed by the delay.
        CHECK(prop<uint32_t>(f, "SpiLastTransfers", 'u') == 5);
        CHECK(prop<uint16_t>(f, "SpiLastDelayUsecs", 'q') == 25);
        CHECK(bytes_prop(f, "Leds", "(yyy)") == std::vector<uint8_t>{7, 8, 9});
    }
    CHECK(prop<uint64_t>(f, "SpiModeMismatches", 't') == 0);
}
