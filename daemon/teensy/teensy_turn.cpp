#include "daemon/teensy/teensy_turn.hpp"

#include "core/clock.hpp"

#include <cmath>

namespace caracara {

Result TeensyTurn::start(double radians, bool absolute, std::string_view client, Completion done) {
    // A turn runs only while the vehicle may move (a kill, a power-off or the command timeout
    // ends it): a second one is Busy whatever the state.
    if (done_)
        return {Status::Busy, "a turn is already running"};
    const Result range = std::isfinite(radians) ? Result{}
                                                : Result{Status::InvalidValue, "the angle must be a finite number of radians"};
    if (Result r = gate_.accept_command(client, connection_.carries(range)); !r.ok())
        return r;
    done_ = std::move(done);
    connection_.telemetry().turning = true;
    const uint64_t id = ++id_;
    TeensyLink& link = connection_.link();
    connection_.command([&link, radians, absolute] { return absolute ? link.turn_to(radians) : link.turn(radians); },
                        absolute ? "Turn to" : "Turn", [this, id](const Result& r) {
                            if (id != id_ || !done_)
                                return; // ended meanwhile (a kill)
                            if (!r.ok()) {
                                finish(r);
                                return;
                            }
                            handshake_ = teensy::ConfirmHandshake();
                            handshake_.start(monotonic_ns());
                            sd_event_source* s = nullptr;
                            uint64_t now_us = 0;
                            sd_event_now(event_, CLOCK_MONOTONIC, &now_us);
                            if (sd_event_add_time(event_, &s, CLOCK_MONOTONIC, now_us, 1, on_step, this) < 0) {
                                finish({Status::Hardware, "cannot schedule the confirmation handshake"});
                                return;
                            }
                            source_.reset(s);
                        });
    return {};
}

int TeensyTurn::on_step(sd_event_source*, uint64_t, void* userdata) {
    static_cast<TeensyTurn*>(userdata)->step();
    return 0;
}

void TeensyTurn::step() {
    // Drive the handshake without blocking: the worker sends what it asks for, then the timer
    // sleeps until it wants the next poll.
    const uint64_t id = id_;
    connection_.worker().submit([this] { step_ = connection_.link().advance(handshake_); },
                                [this, id] {
                                    if (id != id_ || !done_)
                                        return;
                                    switch (step_.action) {
                                    case teensy::ConfirmHandshake::Action::Wait:
                                        sd_event_source_set_time(source_.get(), step_.at_ns / 1000);
                                        sd_event_source_set_enabled(source_.get(), SD_EVENT_ONESHOT);
                                        return;
                                    case teensy::ConfirmHandshake::Action::Done:
                                        finish({});
                                        return;
                                    case teensy::ConfirmHandshake::Action::Send: // advance() never stops on a Send
                                    case teensy::ConfirmHandshake::Action::Failed:
                                    case teensy::ConfirmHandshake::Action::Idle:
                                        finish(teensy::result_of(step_.error == teensy::TeensyError::None
                                                                     ? teensy::TeensyError::LinkError
                                                                     : step_.error,
                                                                 "turn confirmation"));
                                        return;
                                    }
                                });
}

void TeensyTurn::finish(const Result& r) {
    ++id_;
    connection_.telemetry().turning = false;
    auto done = std::move(done_);
    done_ = nullptr;
    source_.reset();
    if (done)
        done(r);
}

} // namespace caracara
