#include "daemon/teensy/teensy_port.hpp"

#include "daemon/loop/log.hpp"

#include <memory>
#include <string>

namespace caracara {

TeensyPort::TeensyPort(sd_event* event, DeviceIo& io, const SpiSettings& settings, CommandGate& gate,
                       FailsafeGate& failsafes, VehicleEvents& events)
    : gate_(gate), events_(events), connection_(event, io, settings, failsafes), turn_(event, connection_, gate) {
    connection_.set_handlers([this] { wheels_moving_ = false; }, [this] { stop_motion(); });
}

void TeensyPort::close() {
    turn_.cancel({Status::Hardware, "the daemon is shutting down"});
    connection_.close();
}

void TeensyPort::stop_motion() {
    wheels_moving_ = false;
    if (!connection_.is_open())
        return;
    TeensyLink& link = connection_.link();
    connection_.command([&link] { return link.stop(0); }, "Stop", [](const Result& r) {
        if (!r.ok())
            log_error("Teensy Stop failed: %s", r.message.c_str());
    });
}

void TeensyPort::stop_if_moving() {
    if (!wheels_moving_ && !turn_.running())
        return;
    stop_motion();
    cancel_turn({Status::Timeout, "the turn was stopped: its command stream ended"});
}

Result TeensyPort::set_leds(int red, int green, int blue, Completion done) {
    if (gate_.powered_off())
        return gate_.state_error();
    for (int v : {red, green, blue})
        if (v < 0 || v > 255)
            return {Status::OutOfRange, "LED values are 0..255"};
    if (Result r = connection_.carries({}); !r.ok())
        return r;
    const std::array<uint8_t, 3> want{static_cast<uint8_t>(red), static_cast<uint8_t>(green), static_cast<uint8_t>(blue)};
    // A packet stream repeats its LEDs at every packet: while the same values are on their way
    // (a slow Teensy), they are not queued again.
    if (!done && leds_out_ == want)
        return {};
    leds_out_ = want;
    TeensyLink& link = connection_.link();
    connection_.command([&link, red, green, blue] { return link.set_leds(red, green, blue); }, "Set LEDs",
                        [this, want, done = std::move(done)](const Result& r) {
                            if (leds_out_ == want)
                                leds_out_.reset();
                            if (r.ok()) {
                                leds_ = want;
                                events_.changed(kChangeLeds);
                            }
                            if (done)
                                done(r);
                        });
    return {};
}

Result TeensyPort::set_speed(int left, int right, std::string_view client, Completion done) {
    // Drive motors are motors: only a ready vehicle moves them, as a command from the commanding
    // client under the command timeout (stopping is always allowed).
    const bool moving = left != 0 || right != 0;
    if (moving) {
        const Result range = teensy::result_of(teensy::encode_set_speed(left, right).error, "Set Speed");
        if (Result r = gate_.accept_command(client, connection_.carries(range)); !r.ok())
            return r;
    }
    TeensyLink& link = connection_.link();
    connection_.command([&link, left, right] { return link.set_speed(left, right); }, "Set Speed",
                        [this, moving, done = std::move(done)](const Result& r) {
                            if (r.ok())
                                wheels_moving_ = moving;
                            if (done)
                                done(r);
                        });
    return {};
}

Result TeensyPort::stop(int duty, Completion done) {
    TeensyLink& link = connection_.link();
    connection_.command([&link, duty] { return link.stop(duty); }, "Stop", std::move(done));
    return {};
}

Result TeensyPort::servo(int id, int degrees, Completion done) {
    if (gate_.powered_off())
        return gate_.state_error();
    TeensyLink& link = connection_.link();
    connection_.command([&link, id, degrees] { return link.servo(id, degrees); }, "Servo",
                        [this, id, degrees, done = std::move(done)](const Result& r) {
                            if (r.ok())
                                connection_.telemetry().servos[static_cast<size_t>(id)] = static_cast<uint8_t>(degrees);
                            if (done)
                                done(r);
                        });
    return {};
}

Result TeensyPort::distance(int sensor, DistanceDone done) {
    auto mm = std::make_shared<uint16_t>(0);
    TeensyLink& link = connection_.link();
    connection_.command(
        [&link, sensor, mm] {
            auto r = link.get_distance(sensor);
            *mm = r.value;
            return r.error;
        },
        "Get distance",
        [this, sensor, mm, done = std::move(done)](const Result& r) {
            std::vector<uint16_t>& distances = connection_.telemetry().distances;
            if (r.ok() && sensor >= 0 && static_cast<size_t>(sensor) < distances.size())
                distances[static_cast<size_t>(sensor)] = *mm;
            if (done)
                done(r, *mm);
        });
    return {};
}

} // namespace caracara
