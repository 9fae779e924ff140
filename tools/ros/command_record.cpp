#include "tools/ros/command_record.hpp"

namespace caracara::ros {

void CommandRecord::commanded(const std::string& writer, uint64_t now_ns) {
    const bool new_holder = holder(now_ns) != writer;
    holder_ = writer;
    holder_last_ns_ = now_ns;
    if (new_holder && changed_)
        changed_();
}

void CommandRecord::left(const std::string& writer) {
    if (holder_ != writer)
        return;
    holder_.clear();
    if (changed_)
        changed_();
}

void CommandRecord::refused(const std::string& writer, CommandRefusal why, const std::string& detail, uint64_t now_ns) {
    ++counts_[static_cast<std::size_t>(why)];
    last_refusal_ = std::string(name_of(why)) + " from writer " + writer + ": " + detail;
    last_refusal_ns_ = now_ns;
    if (changed_)
        changed_();
}

std::string CommandRecord::holder(uint64_t now_ns) const {
    return !holder_.empty() && now_ns <= holder_last_ns_ + timeout_ns_ ? holder_ : std::string();
}

uint64_t CommandRecord::refusals() const {
    uint64_t n = 0;
    for (const uint64_t c : counts_)
        n += c;
    return n;
}

} // namespace caracara::ros
