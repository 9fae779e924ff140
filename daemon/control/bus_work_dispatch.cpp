#include "daemon/control/bus_work_dispatch.hpp"

#include "drivers/platform/io_error.hpp"

#include <poll.h>

namespace caracara {

namespace {
constexpr int kTransactionsPerDispatch = 32;
} // namespace

BusWorkDispatch::BusWorkDispatch(sd_event* event, ThrusterBus& bus, TeensyPort& teensy, SafetyLines& lines,
                                 std::function<void()> cycle_work_done, std::function<void()> resumed,
                                 std::function<void()> command_handed_over)
    : event_(event),
      bus_(bus),
      teensy_(teensy),
      lines_(lines),
      cycle_work_done_(std::move(cycle_work_done)),
      resumed_(std::move(resumed)),
      command_handed_over_(std::move(command_handed_over)),
      orders_(bus) {}

std::string BusWorkDispatch::start() {
    sd_event_source* s = nullptr;
    int r = sd_event_add_defer(event_, &s, on_work, this);
    if (r < 0)
        return "sd_event_add_defer: " + errno_name(-r);
    work_source_.reset(s);
    sd_event_source_set_priority(s, kWorkPriority);
    sd_event_source_set_enabled(s, SD_EVENT_OFF);

    r = sd_event_add_defer(event_, &s, on_resume, this);
    if (r < 0)
        return "sd_event_add_defer: " + errno_name(-r);
    resume_source_.reset(s);
    sd_event_source_set_priority(s, kAnnouncePriority + 1);
    sd_event_source_set_enabled(s, SD_EVENT_OFF);
    return {};
}

void BusWorkDispatch::stop() {
    work_source_.reset();
    resume_source_.reset();
}

bool BusWorkDispatch::input_pending() const {
    // Something for a higher-priority source: a D-Bus message (read already, or on the
    // socket) or a kill switch edge. One poll() instead of a full event-loop iteration.
    if (!input_ || input_->queued())
        return true;
    pollfd fds[2]{{input_->fd(), POLLIN, 0}, {lines_.kill_switch_fd(), POLLIN, 0}};
    return ::poll(fds, 2, 0) != 0;
}

void BusWorkDispatch::step_aside() {
    sd_event_source_set_enabled(work_source_.get(), SD_EVENT_OFF);
    sd_event_source_set_enabled(resume_source_.get(), SD_EVENT_ONESHOT);
}

void BusWorkDispatch::pause() {
    sd_event_source_set_enabled(work_source_.get(), SD_EVENT_OFF);
}

int BusWorkDispatch::on_work(sd_event_source*, void* userdata) {
    auto* self = static_cast<BusWorkDispatch*>(userdata);
    // The transfers of this pass wake the bus worker once, at its end (whichever way it ends).
    self->bus_.worker().hold_wakeups();
    struct Release {
        ThrusterBus& bus;
        ~Release() { bus.worker().release_wakeups(); }
    } release{self->bus_};
    // The cycle's transfers are handed to the bus worker as one batch (orders first; see
    // BusWorker::submit); the Teensy's slots run here meanwhile. The end of the batch
    // (ControlLoop::bus_done) brings the work back to close the cycle.
    for (int n = 0; n < kTransactionsPerDispatch; ++n) {
        const Work w = self->work_one();
        if (w == Work::Transfer)
            continue;
        if (w == Work::Waiting) {
            if (self->command_out_) {
                self->bus_.worker().wake_when_done(); // a command's orders: its properties follow the wire at once
                self->command_handed_over_();
            }
            self->command_out_ = false;
            sd_event_source_set_enabled(self->work_source_.get(), SD_EVENT_OFF);
            return 0;
        }
        if (w == Work::None) {
            self->cycle_work_done_();
            return 0;
        }
        if (self->input_pending())
            return 0;
    }
    return 0;
}

int BusWorkDispatch::on_resume(sd_event_source*, void* userdata) {
    static_cast<BusWorkDispatch*>(userdata)->resumed_();
    return 0;
}

void BusWorkDispatch::schedule_work() {
    // sd-event turns a one-shot source off before dispatching it, so "resume pending" is
    // exactly "resume source enabled": a tick or a command in between must not put the work
    // back in front of the announcements.
    int resume_pending = SD_EVENT_OFF;
    if (resume_source_)
        sd_event_source_get_enabled(resume_source_.get(), &resume_pending);
    if (work_source_ && resume_pending == SD_EVENT_OFF)
        sd_event_source_set_enabled(work_source_.get(), SD_EVENT_ON);
}

void BusWorkDispatch::start_cycle(uint32_t status_reads) {
    orders_.start_cycle(status_reads, teensy_.is_open());
    // The cycle's transfers are handed to the bus worker right here (a few microseconds: no
    // transfer runs on this thread), not in another event-loop iteration; unless the work has
    // stepped aside for the announcements, when it resumes after them.
    // The work source stays on if it returns early (input waiting), as when dispatched.
    schedule_work();
    int work_on = SD_EVENT_OFF;
    sd_event_source_get_enabled(work_source_.get(), &work_on);
    if (work_on != SD_EVENT_OFF)
        on_work(work_source_.get(), this);
}

BusWorkDispatch::Work BusWorkDispatch::work_one() {
    switch (orders_.hand_over_next()) {
    case OrderSchedule::Kind::Order:
    case OrderSchedule::Kind::Status: return Work::Transfer;
    case OrderSchedule::Kind::Teensy:
        teensy_.poll();
        return Work::Other;
    case OrderSchedule::Kind::None: break;
    }
    // The cycle ends once its transfers are done too.
    return bus_.worker().idle() ? Work::None : Work::Waiting;
}

void BusWorkDispatch::demand_changed(const MotorValues& orders) {
    if (orders_.demand_changed(orders)) {
        command_out_ = true;
        schedule_work();
    }
}

} // namespace caracara
