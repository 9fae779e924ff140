// Who pilots the vehicle: the bus clients (unique names) whose motion commands were taken since
// it was last armed, and whether one of them left with none remaining, the pilot-lost
// failsafe's condition. A client that only reads, kills or clears a kill is no pilot. Pure
// logic, owned by the SafetyMachine, which knows when the vehicle is armed.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace caracara {

class PilotRoster {
public:
    // A motion command from `client` was taken: it pilots (a new one ends a loss).
    void commanded(std::string_view client);
    // `client` left the bus; true when it was a pilot.
    bool left(std::string_view client);
    // Armed again, killed or powered off: nobody pilots, nobody was lost.
    void clear();
    // A pilot left, and no pilot is connected.
    bool lost() const { return lost_ && connected_.empty(); }
    std::size_t connected() const { return connected_.size(); }

private:
    std::vector<std::string> connected_; // a few at most: a laptop, a second tab
    bool lost_ = false;
};

} // namespace caracara
