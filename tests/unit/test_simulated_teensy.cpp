// The simulated Teensy driven with raw frames exactly as spidev would clock them, with every
// expected byte encoded by hand (not through a codec), and the attitude model's signs.
#include "sim/teensy_model.hpp"
#include "sim/vehicle_body.hpp"

#include <algorithm>
#include "tests/catch.hpp"
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

using namespace caracara::sim;
using caracara::kMotorMax;
using caracara::VehicleGeometry;
using caracara::WrenchMotors;
namespace frames = caracara::frames;
using Bytes = std::vector<uint8_t>;

namespace {

std::array<double, 8> no_thrust() { return {}; }

// One SPI_IOC_MESSAGE with a single transfer, chip select released afterwards.
Bytes frame(TeensyModel& t, const Bytes& tx, uint64_t now = 0) {
    Bytes rx(tx.size(), 0xEE);
    t.transfer(tx, rx, SpiTransferParams{}, now);
    t.end_message(now);
    return rx;
}

// One SPI_IOC_MESSAGE with one 1-byte transfer per byte (chip select stays asserted).
Bytes frame_bytewise(TeensyModel& t, const Bytes& tx, uint64_t now = 0) {
    Bytes rx(tx.size(), 0xEE);
    for (std::size_t i = 0; i < tx.size(); ++i)
        t.transfer(std::span<const uint8_t>(&tx[i], 1), std::span<uint8_t>(&rx[i], 1), SpiTransferParams{}, now);
    t.end_message(now);
    return rx;
}

float le_f32(const Bytes& b, std::size_t off) {
    uint32_t u = uint32_t(b[off]) | uint32_t(b[off + 1]) << 8 | uint32_t(b[off + 2]) << 16 | uint32_t(b[off + 3]) << 24;
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}

struct Rig {
    VehicleBody body{no_thrust};
    TeensyModel teensy;
    explicit Rig(TeensyConfig cfg = {}) : teensy(cfg, body) {}
};

} // namespace

TEST_CASE("Get orientation answers float32 little-endian with the command as ack") {
    Rig r;
    r.body.set_attitude({std::numbers::pi / 2, 0.25, -0.5});
    // [08 axis | 4 answer | ack]; float(pi/2) = 0x3FC90FDB.
    CHECK(frame(r.teensy, {0x08, 0x00, 0, 0, 0, 0, 0}) == Bytes{0x00, 0x00, 0xDB, 0x0F, 0xC9, 0x3F, 0x08});
    Bytes pitch = frame(r.teensy, {0x08, 0x01, 0, 0, 0, 0, 0});
    CHECK(pitch[6] == 0x08);
    CHECK(le_f32(pitch, 2) == 0.25f);
    Bytes roll = frame(r.teensy, {0x08, 0x02, 0, 0, 0, 0, 0});
    CHECK(roll[6] == 0x08);
    CHECK(le_f32(roll, 2) == -0.5f);
    CHECK(r.teensy.frames().commands_executed(0x08) == 3);
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Ok) == 3);
}

TEST_CASE("one 1-byte transfer per byte gives the same frame as one transfer") {
    Rig r;
    r.body.set_attitude({std::numbers::pi / 2, 0, 0});
    CHECK(frame_bytewise(r.teensy, {0x08, 0x00, 0, 0, 0, 0, 0}) ==
          Bytes{0x00, 0x00, 0xDB, 0x0F, 0xC9, 0x3F, 0x08});
    CHECK(frame_bytewise(r.teensy, {0x09, 0x0A, 0x0B, 0x0C, 0x00}) == Bytes{0, 0, 0, 0, 0x09});
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{0x0A, 0x0B, 0x0C});
}

TEST_CASE("two frames back to back in one message are both served") {
    Rig r;
    r.body.set_attitude({1.0, 0, 0});
    Bytes rx = frame(r.teensy, {0x09, 1, 2, 3, 0, 0x08, 0x00, 0, 0, 0, 0, 0});
    CHECK(rx[4] == 0x09);
    CHECK(rx[11] == 0x08);
    CHECK(le_f32(rx, 7) == 1.0f);
}

TEST_CASE("chip select released mid-frame discards the frame and resynchronises") {
    Rig r;
    CHECK(frame(r.teensy, {0x09, 0x10, 0x20}) == Bytes{0, 0, 0});
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{0, 0, 0});
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Incomplete) == 1);
    // Cut after data but before the ack slot: still no effect (a Turn resend must not double).
    frame(r.teensy, {0x03, 0x00, 0x00, 0x00, 0x3F});
    CHECK(r.teensy.task_state() == TeensyTaskState::Idle);
    CHECK(r.teensy.frames().commands_executed(0x03) == 0);
    // The rest of a frame in the next message is not glued on: 0x00 is no command.
    frame(r.teensy, {0x08});
    CHECK(frame(r.teensy, {0x00, 0, 0, 0, 0, 0}) == Bytes{0, 0, 0, 0, 0, 0});
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Unknown) == 1);
    // And the next whole frame works.
    CHECK(frame(r.teensy, {0x09, 0x10, 0x20, 0x30, 0}) == Bytes{0, 0, 0, 0, 0x09});
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{0x10, 0x20, 0x30});
}

TEST_CASE("unknown command answers zeros until chip select release") {
    Rig r;
    CHECK(frame(r.teensy, {0x42, 1, 2, 3, 4, 5}) == Bytes{0, 0, 0, 0, 0, 0});
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Unknown) == 1);
    CHECK(r.teensy.frames().commands_received(0x42) == 1);
    auto log = r.teensy.frames().records();
    REQUIRE(log.size() == 1);
    CHECK(log[0].name == "Unknown");
    CHECK(log[0].mosi == Bytes{0x42, 1, 2, 3, 4, 5});
    CHECK(frame(r.teensy, {0x05, 0x00, 0x00}) == Bytes{0, 0, 0x05});
}

TEST_CASE("injected busy answers 0xFF in the ack slot for N frames without executing them") {
    Rig r;
    r.body.set_attitude({1.0, 0, 0});
    r.teensy.faults().inject_busy(2);
    CHECK(frame(r.teensy, {0x09, 7, 8, 9, 0}) == Bytes{0, 0, 0, 0, 0xFF});
    CHECK(frame(r.teensy, {0x08, 0x00, 0, 0, 0, 0, 0}) == Bytes{0, 0, 0, 0, 0, 0, 0xFF});
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{0, 0, 0});
    CHECK(r.teensy.faults().pending_busy() == 0);
    CHECK(frame(r.teensy, {0x09, 7, 8, 9, 0}) == Bytes{0, 0, 0, 0, 0x09});
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{7, 8, 9});
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Busy) == 2);
    CHECK(r.teensy.frames().commands_received(0x09) == 2);
    CHECK(r.teensy.frames().commands_executed(0x09) == 1);
}

TEST_CASE("random busy is reproducible from its seed and never executes a busy frame") {
    auto run = [](uint64_t seed) {
        Rig r;
        REQUIRE(r.teensy.faults().set_random_busy(0.5, seed));
        Bytes acks;
        for (int i = 0; i < 200; ++i)
            acks.push_back(frame(r.teensy, {0x05, 0x00, 0x00})[2]);
        CHECK(r.teensy.frames().commands_executed(0x05) == r.teensy.frames().outcome_count(TeensyFrameOutcome::Ok));
        CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Busy) + r.teensy.frames().outcome_count(TeensyFrameOutcome::Ok) == 200);
        return acks;
    };
    Bytes a = run(42);
    CHECK(a == run(42));
    CHECK(a != run(43));
    auto busy = std::count(a.begin(), a.end(), uint8_t{0xFF});
    auto ok = std::count(a.begin(), a.end(), uint8_t{0x05});
    CHECK(busy + ok == 200);
    CHECK(busy > 60);
    CHECK(ok > 60);
    Rig r;
    CHECK_FALSE(r.teensy.faults().set_random_busy(1.5, 1));
    CHECK_FALSE(r.teensy.faults().set_random_busy(std::nan(""), 1));
}

TEST_CASE("garbage ack corrupts only the ack; no answer is all zeros and not executed") {
    Rig r;
    r.teensy.set_distance_mm(0, 0x0102);
    r.teensy.faults().inject_garbage_ack(1);
    CHECK(frame(r.teensy, {0x07, 0x00, 0, 0, 0}) == Bytes{0, 0, 0x02, 0x01, uint8_t(0x07 ^ 0xA5)});
    CHECK(frame(r.teensy, {0x07, 0x00, 0, 0, 0}) == Bytes{0, 0, 0x02, 0x01, 0x07});
    // The slave heard a garbage-ack frame (only MISO was corrupted), so it took effect.
    r.teensy.faults().inject_garbage_ack(1);
    CHECK(frame(r.teensy, {0x09, 1, 1, 1, 0})[4] == (0x09 ^ 0xA5));
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{1, 1, 1});

    r.teensy.faults().inject_no_answer(2);
    CHECK(frame(r.teensy, {0x07, 0x00, 0, 0, 0}) == Bytes{0, 0, 0, 0, 0});
    CHECK(frame(r.teensy, {0x09, 2, 2, 2, 0}) == Bytes{0, 0, 0, 0, 0});
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{1, 1, 1});
    CHECK(frame(r.teensy, {0x09, 2, 2, 2, 0}) == Bytes{0, 0, 0, 0, 0x09});
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::GarbageAck) == 2);
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::NoAnswer) == 2);

    r.teensy.faults().inject_busy(3);
    r.teensy.faults().clear();
    CHECK(frame(r.teensy, {0x05, 0, 0}) == Bytes{0, 0, 0x05});
}

TEST_CASE("Turn, poll Confirm until 0xFF, acknowledge with a positive value, task idle") {
    TeensyConfig cfg;
    cfg.turn_rate_rad_s = 1.0;
    Rig r(cfg);
    // Turn by 0.5 rad: float 0x3F000000.
    CHECK(frame(r.teensy, {0x03, 0x00, 0x00, 0x00, 0x3F, 0x00}) == Bytes{0, 0, 0, 0, 0, 0x03});
    CHECK(r.teensy.task_state() == TeensyTaskState::Running);
    CHECK(r.teensy.last_turn_rad() == 0.5f);

    // Confirm: [01 | answer | ack]; still turning -> answer 0.
    CHECK(frame(r.teensy, {0x01, 0x00, 0x00}) == Bytes{0, 0x00, 0x01});
    r.teensy.step(0.25, 0);
    CHECK(r.teensy.orientation().yaw == Approx(0.25));
    CHECK(frame(r.teensy, {0x01, 0x00, 0x00}) == Bytes{0, 0x00, 0x01});
    // A positive value while the task runs is not an acknowledgement.
    CHECK(frame(r.teensy, {0x01, 0x01, 0x00}) == Bytes{0, 0x00, 0x01});
    CHECK(r.teensy.acknowledgements() == 0);
    r.teensy.step(0.3, 0);
    CHECK(r.teensy.task_state() == TeensyTaskState::FinishedAwaitingAck);
    CHECK(r.teensy.orientation().yaw == Approx(0.5));

    // Finished -> 0xFF, repeated until the host acknowledges.
    CHECK(frame(r.teensy, {0x01, 0x00, 0x00}) == Bytes{0, 0xFF, 0x01});
    CHECK(frame(r.teensy, {0x01, 0x00, 0x00}) == Bytes{0, 0xFF, 0x01});
    CHECK(r.teensy.task_state() == TeensyTaskState::FinishedAwaitingAck);
    // The acknowledgement travels in the answer slot on MOSI.
    CHECK(frame(r.teensy, {0x01, 0x01, 0x00}) == Bytes{0, 0xFF, 0x01});
    CHECK(r.teensy.task_state() == TeensyTaskState::Idle);
    CHECK(r.teensy.acknowledgements() == 1);
    CHECK(frame(r.teensy, {0x01, 0x00, 0x00}) == Bytes{0, 0x00, 0x01});

    // The heading answer follows the turn.
    CHECK(le_f32(frame(r.teensy, {0x08, 0x00, 0, 0, 0, 0, 0}), 2) == Approx(0.5));
}

TEST_CASE("a busy acknowledgement is not taken; the resend is") {
    Rig r;
    frame(r.teensy, {0x03, 0x00, 0x00, 0x00, 0x3F, 0x00});
    r.teensy.step(1.0, 0);
    r.teensy.faults().inject_busy(1);
    CHECK(frame(r.teensy, {0x01, 0x01, 0x00}) == Bytes{0, 0x00, 0xFF});
    CHECK(r.teensy.task_state() == TeensyTaskState::FinishedAwaitingAck);
    CHECK(frame(r.teensy, {0x01, 0x01, 0x00}) == Bytes{0, 0xFF, 0x01});
    CHECK(r.teensy.task_state() == TeensyTaskState::Idle);
}

TEST_CASE("Turn to goes the shortest way to an absolute heading") {
    Rig r;
    r.body.set_attitude({3.0, 0, 0});
    // Turn to -3.0 rad: float 0xC0400000; shortest way is +(2pi - 6) = +0.283 rad.
    CHECK(frame(r.teensy, {0x04, 0x00, 0x00, 0x40, 0xC0, 0x00}) == Bytes{0, 0, 0, 0, 0, 0x04});
    CHECK(r.teensy.last_turn_to_rad() == -3.0f);
    CHECK(r.teensy.turn_remaining_rad() == Approx(2 * std::numbers::pi - 6.0));
    r.teensy.step(0.1, 0);
    CHECK(r.teensy.orientation().yaw == Approx(3.1));
    r.teensy.step(1.0, 0);
    CHECK(r.teensy.task_state() == TeensyTaskState::FinishedAwaitingAck);
    CHECK(r.teensy.orientation().yaw == Approx(-3.0));
    // NaN (0x7FC00000) is refused: ack 0x00.
    CHECK(frame(r.teensy, {0x04, 0x00, 0x00, 0xC0, 0x7F, 0x00}) == Bytes{0, 0, 0, 0, 0, 0x00});
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Invalid) == 1);
}

TEST_CASE("Stop zeroes the wheels, keeps the duty and finishes a running turn") {
    Rig r;
    frame(r.teensy, {0x02, 0x10, 0x10, 0x00});
    frame(r.teensy, {0x03, 0x00, 0x00, 0x80, 0x3F, 0x00}); // Turn 1.0
    r.teensy.step(0.2, 0);
    CHECK(frame(r.teensy, {0x05, 0x80, 0x00}) == Bytes{0, 0, 0x05});
    CHECK(r.teensy.stop_duty() == 0x80);
    CHECK(r.teensy.wheels().front_left == 0.0);
    CHECK(r.teensy.wheels().back_right == 0.0);
    CHECK(r.teensy.task_state() == TeensyTaskState::FinishedAwaitingAck);
    CHECK(r.teensy.orientation().yaw == Approx(0.2));
    CHECK(frame(r.teensy, {0x01, 0x00, 0x00}) == Bytes{0, 0xFF, 0x01});
}

TEST_CASE("Set Speed applies the seed's rear-wheel formula") {
    TeensyConfig cfg;
    cfg.wheel_k = 0.8;
    cfg.front_circumference = 0.3;
    cfg.back_circumference = 0.2;
    Rig r(cfg);
    // left = 100 (0x64), right = -20 (0xEC): v2 = 100, v1 = -20, k*Df/Db = 1.2.
    CHECK(frame(r.teensy, {0x02, 0x64, 0xEC, 0x00}) == Bytes{0, 0, 0, 0x02});
    TeensyWheels w = r.teensy.wheels();
    CHECK(w.front_left == 100.0);
    CHECK(w.front_right == -20.0);
    CHECK(w.back_left == Approx(1.2 * (40.0 + 120.0)));  // 192
    CHECK(w.back_right == Approx(1.2 * (40.0 - 120.0))); // -96
    // Straight ahead: both rear wheels at k*Df/Db times the front speed.
    frame(r.teensy, {0x02, 0x32, 0x32, 0x00});
    CHECK(r.teensy.wheels().back_left == Approx(60.0));
    CHECK(r.teensy.wheels().back_right == Approx(60.0));
}

TEST_CASE("LEDs, servos and distance sensors") {
    Rig r;
    CHECK(frame(r.teensy, {0x09, 0xFF, 0x80, 0x01, 0x00}) == Bytes{0, 0, 0, 0, 0x09});
    CHECK(r.teensy.leds() == std::array<uint8_t, 3>{0xFF, 0x80, 0x01});

    CHECK(r.teensy.servo_degrees() == std::vector<uint8_t>{90, 90, 90, 90});
    CHECK(frame(r.teensy, {0x06, 0x02, 0x2D, 0x00}) == Bytes{0, 0, 0, 0x06});
    CHECK(r.teensy.servo_degrees()[2] == 45);
    CHECK(frame(r.teensy, {0x06, 0x04, 0x10, 0x00}) == Bytes{0, 0, 0, 0x00}); // no servo 4
    CHECK(frame(r.teensy, {0x06, 0x01, 0xB5, 0x00}) == Bytes{0, 0, 0, 0x00}); // 181 degrees
    CHECK(frame(r.teensy, {0x06, 0x01, 0xB4, 0x00}) == Bytes{0, 0, 0, 0x06}); // 180 degrees
    CHECK(r.teensy.servo_degrees() == std::vector<uint8_t>{90, 180, 45, 90});

    REQUIRE(r.teensy.set_distance_mm(1, 0x1234));
    CHECK_FALSE(r.teensy.set_distance_mm(4, 1));
    CHECK(frame(r.teensy, {0x07, 0x01, 0x00, 0x00, 0x00}) == Bytes{0, 0, 0x34, 0x12, 0x07});
    CHECK(frame(r.teensy, {0x07, 0x00, 0x00, 0x00, 0x00}) == Bytes{0, 0, 0xE8, 0x03, 0x07}); // 1000 mm
    CHECK(frame(r.teensy, {0x07, 0x04, 0x00, 0x00, 0x00}) == Bytes{0, 0, 0, 0, 0x00});
    CHECK(frame(r.teensy, {0x08, 0x03, 0, 0, 0, 0, 0}) == Bytes{0, 0, 0, 0, 0, 0, 0x00}); // axis 3
    CHECK(r.teensy.frames().outcome_count(TeensyFrameOutcome::Invalid) == 4);
}

TEST_CASE("the frame log is a bounded ring of raw bytes and outcomes") {
    TeensyConfig cfg;
    cfg.log_capacity = 4;
    Rig r(cfg);
    for (uint8_t i = 0; i < 9; ++i)
        frame(r.teensy, {0x09, i, 0, 0, 0}, 1000u + i);
    r.teensy.faults().inject_busy(1);
    frame(r.teensy, {0x05, 0x01, 0x00}, 2000);
    auto log = r.teensy.frames().records();
    REQUIRE(log.size() == 4);
    CHECK(r.teensy.frames().total() == 10);
    CHECK(log[0].seq == 6);
    CHECK(log[2].start_ns == 1008);
    CHECK(log[2].mosi == Bytes{0x09, 8, 0, 0, 0});
    CHECK(log[2].miso == Bytes{0, 0, 0, 0, 0x09});
    CHECK(log[2].name == "SetLeds");
    CHECK(log[3].outcome == TeensyFrameOutcome::Busy);
    CHECK(caracara::name_of(log[3].outcome) == "busy");
    CHECK(log[3].miso == Bytes{0, 0, 0xFF});
}

TEST_CASE("VehicleBody: sustained yaw thrust turns clockwise, pitch and roll settle back") {
    std::array<double, 8> thrust{};
    VehicleBody body([&] { return thrust; });
    // Seed: clockwise from above = motors 0, 2 positive, 4, 6 negative.
    thrust = {+1, 0, +1, 0, -1, 0, -1, 0};
    auto f = body.generalised_force();
    CHECK(f[3] == Approx(1.0));
    CHECK(f[0] == Approx(0.0));
    CHECK(f[1] == Approx(0.0));
    body.step(0.5, 0);
    CHECK(body.yaw() > 0.1);
    double unwrapped = body.yaw();
    double prev = body.yaw();
    for (int i = 0; i < 200; ++i) {
        body.step(0.05, 0);
        double d = body.yaw() - prev;
        unwrapped += VehicleBody::wrap_angle(d);
        prev = body.yaw();
        CHECK(body.yaw() > -std::numbers::pi);
        CHECK(body.yaw() <= std::numbers::pi);
    }
    // Steady rate k_torque / k_damp = 1 rad/s: about 10 rad after 10.5 s (so it wrapped).
    CHECK(body.rates().yaw == Approx(1.0).epsilon(0.01));
    CHECK(unwrapped > 8.5);
    CHECK(body.pitch() == Approx(0.0).margin(1e-9));

    // Counter-clockwise is the mirror image.
    body.reset();
    thrust = {-1, 0, -1, 0, +1, 0, +1, 0};
    body.step(1.0, 0);
    CHECK(body.yaw() < -0.1);

    // Nose up: 3, 5 positive, 1, 7 negative; the bottom-heavy body holds a tilt, then rights itself.
    body.reset();
    thrust = {0, -1, 0, +1, 0, +1, 0, -1};
    body.step(3.0, 0);
    CHECK(body.pitch() > 0.3);
    CHECK(body.roll() == Approx(0.0).margin(1e-9));
    CHECK(body.position().depth == Approx(0.0).margin(1e-9)); // z forces cancel
    thrust = {};
    body.step(10.0, 0);
    CHECK(body.pitch() == Approx(0.0).margin(0.01));

    // Roll clockwise from the back: 5, 7 positive, 1, 3 negative.
    body.reset();
    thrust = {0, -1, 0, -1, 0, +1, 0, +1};
    body.step(3.0, 0);
    CHECK(body.roll() > 0.3);
    thrust = {};
    body.step(10.0, 0);
    CHECK(body.roll() == Approx(0.0).margin(0.01));

    // Released from a tilt with no thrust at all.
    body.reset();
    body.set_attitude({0.0, 0.6, -0.7});
    body.step(10.0, 0);
    CHECK(body.pitch() == Approx(0.0).margin(0.01));
    CHECK(body.roll() == Approx(0.0).margin(0.01));
}

TEST_CASE("VehicleBody: translation follows the axis table and the heading") {
    std::array<double, 8> thrust{};
    VehicleBody body([&] { return thrust; });
    thrust = {+1, 0, +1, 0, +1, 0, +1, 0}; // forward
    body.step(5.0, 0);
    CHECK(body.position().y > 3.0);
    CHECK(body.position().x == Approx(0.0).margin(1e-9));
    CHECK(body.yaw() == Approx(0.0).margin(1e-9));

    body.reset();
    thrust = {0, +1, 0, +1, 0, +1, 0, +1}; // deeper
    body.step(2.0, 0);
    CHECK(body.position().depth > 0.5);
    thrust = {0, -1, 0, -1, 0, -1, 0, -1}; // up, but not above the surface
    body.step(20.0, 0);
    CHECK(body.position().depth == 0.0);

    // Facing starboard (yaw +pi/2, clockwise from above), forward thrust moves it to
    // starboard, which is -x in the world frame.
    body.reset();
    body.set_attitude({std::numbers::pi / 2, 0, 0});
    thrust = {+1, 0, +1, 0, +1, 0, +1, 0};
    body.step(5.0, 0);
    CHECK(body.position().x < -3.0);
    CHECK(body.position().y == Approx(0.0).margin(1e-6));

    thrust = {5.0, 0, std::nan(""), 0, 0, 0, 0, 0}; // out-of-range input is clamped / ignored
    auto f = body.generalised_force();
    CHECK(f[3] == Approx(0.25));
}

TEST_CASE("with the vehicle's mass, thrust in newtons accelerates the body by F = m a") {
    // The description caracara-ros maps a Wrench through: 10 N forward on an 11.5 kg vehicle is
    // 10 / 11.5 m/s^2 forward at the start (drag, k_drag * v, still nothing), at an odd heading.
    VehicleBodyConfig cfg;
    cfg.vehicle = VehicleGeometry();
    cfg.vehicle->mass_kg = 11.5;
    cfg.vehicle->inertia_kg_m2 = frames::Vec3{0.2, 0.3, 0.4};
    const WrenchMotors m = cfg.vehicle->motors_for({{10, 0, 0}, {}});
    std::array<double, 8> thrust{};
    for (std::size_t i = 0; i < 8; ++i)
        thrust[i] = m.motors[i] / double(kMotorMax);
    VehicleBody body([&] { return thrust; }, cfg);
    body.set_attitude({0.6, 0, 0});
    const auto a = body.thrust_acceleration();
    CHECK(a[static_cast<std::size_t>(BodyAxis::Y)] == Approx(10 / 11.5).epsilon(0.002)); // forward
    for (BodyAxis other : {BodyAxis::X, BodyAxis::Z, BodyAxis::Yaw, BodyAxis::Pitch, BodyAxis::Roll})
        CHECK(a[static_cast<std::size_t>(other)] == Approx(0).margin(1e-3));
    body.step(0.01, 0);
    // The world's forward at yaw 0.6 (clockwise from above) is (-sin, cos).
    const double v = 0.01 * 10 / 11.5;
    CHECK(body.velocity().x == Approx(-std::sin(0.6) * v).epsilon(0.01));
    CHECK(body.velocity().y == Approx(std::cos(0.6) * v).epsilon(0.01));
    // 1 N m about up (REP 103: counter-clockwise from above) on 0.4 kg m^2: yaw (clockwise) -2.5 rad/s^2.
    const WrenchMotors t = cfg.vehicle->motors_for({{}, {0, 0, 1}});
    for (std::size_t i = 0; i < 8; ++i)
        thrust[i] = t.motors[i] / double(kMotorMax);
    CHECK(body.thrust_acceleration()[static_cast<std::size_t>(BodyAxis::Yaw)] == Approx(-2.5).epsilon(0.01));
    // Without a mass, the normalised model as before: k_force and k_torque times the generalised force.
    VehicleBody plain([&] { return thrust; });
    const auto f = plain.generalised_force();
    for (std::size_t j = 0; j < 6; ++j)
        CHECK(plain.thrust_acceleration()[j] == Approx((j < 3 ? 1.0 : 2.0) * f[j]));
}

TEST_CASE("the Teensy reports the body's yaw as thrusters turn it") {
    std::array<double, 8> thrust{};
    VehicleBody body([&] { return thrust; });
    TeensyModel teensy(TeensyConfig{}, body);
    thrust = {+1, 0, +1, 0, -1, 0, -1, 0};
    body.step(1.0, 0);
    Bytes rx = frame(teensy, {0x08, 0x00, 0, 0, 0, 0, 0});
    CHECK(rx[6] == 0x08);
    CHECK(le_f32(rx, 2) > 0.1f);
    CHECK(le_f32(rx, 2) == Approx(body.yaw()));
}
