#include "sim/teensy_frame_log.hpp"

#include <utility>

namespace caracara::sim {

void TeensyFrameLog::add(TeensyFrameRecord r) {
    ++outcomes_[static_cast<std::size_t>(r.outcome)];
    r.seq = next_seq_++;
    if (log_.size() >= capacity_)
        log_.pop_front();
    log_.push_back(std::move(r));
}

} // namespace caracara::sim
