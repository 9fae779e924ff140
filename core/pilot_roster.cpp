#include "core/pilot_roster.hpp"

#include <algorithm>

namespace caracara {

void PilotRoster::commanded(std::string_view client) {
    // Each command of a stream comes here: the common case is a pilot already known.
    if (std::find(connected_.begin(), connected_.end(), client) == connected_.end())
        connected_.emplace_back(client);
}

bool PilotRoster::left(std::string_view client) {
    const auto it = std::find(connected_.begin(), connected_.end(), client);
    if (it == connected_.end())
        return false;
    connected_.erase(it);
    lost_ = true;
    return true;
}

void PilotRoster::clear() {
    connected_.clear();
    lost_ = false;
}

} // namespace caracara
