#include "sim/wire_log.hpp"

#include <algorithm>
#include <ctime>

namespace caracara::sim {

uint64_t WireLog::append(WireEntry e) {
    e.index = next_++;
    entries_.push_back(std::move(e));
    while (entries_.size() > capacity_)
        entries_.pop_front();
    return entries_.back().index;
}

std::vector<const WireEntry*> WireLog::since(uint64_t since_index, size_t max_entries) const {
    std::vector<const WireEntry*> out;
    auto it = std::lower_bound(entries_.begin(), entries_.end(), since_index,
                               [](const WireEntry& e, uint64_t i) { return e.index < i; });
    for (; it != entries_.end() && out.size() < max_entries; ++it)
        out.push_back(&*it);
    return out;
}

} // namespace caracara::sim
