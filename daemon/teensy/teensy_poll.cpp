#include "daemon/teensy/teensy_poll.hpp"

#include "core/clock.hpp"

#include <cerrno>

namespace caracara {

void TeensyPoll::ask() {
    const unsigned sensors = static_cast<unsigned>(tm_.distances.size());
    const unsigned slots = 3 + (sensors ? 1 : 0);
    frame_.slot = index_ % slots;
    ++index_;
    frame_.sensor = sensors ? (index_ / slots) % sensors : 0;
    out_ = true;
    // Captures `this` only: no allocation per poll.
    worker_.submit(
        [this] {
            teensy::TeensyError e = teensy::TeensyError::None;
            if (frame_.slot < 3) {
                auto r = link_.get_orientation(static_cast<int>(frame_.slot));
                e = r.error;
                frame_.value = r.value;
            } else {
                auto r = link_.get_distance(static_cast<int>(frame_.sensor));
                e = r.error;
                frame_.value = r.value;
            }
            frame_.ok = e == teensy::TeensyError::None;
            frame_.read_ns = monotonic_ns();
            frame_.err = io_errno_(e);
        },
        [this] { answered(); }, false);
}

void TeensyPoll::answered() {
    out_ = false;
    if (frame_.ok) {
        if (frame_.slot >= 3) {
            tm_.distances[frame_.sensor] = static_cast<uint16_t>(frame_.value);
        } else {
            tm_.orientation_polled_ns = frame_.read_ns;
            if (tm_.orientation[frame_.slot] != frame_.value) {
                tm_.orientation[frame_.slot] = frame_.value;
                tm_.orientation_read_ns = frame_.read_ns;
            }
        }
    }
    done_(frame_.ok ? Outcome::Answered : frame_.err == ENODEV ? Outcome::Gone : Outcome::Failed);
}

} // namespace caracara
