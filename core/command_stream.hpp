// The command stream the safety machine watches: whether one is live, from which client, and
// when its last command came. SafetyMachine owns it and decides when it starts (a command
// accepted in Ready) and stops (its timeout, its client leaving, any change of state); callers
// read it through SafetyMachine::commands().
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace caracara {

class CommandStream final {
public:
    // A command from `client` (its unique name on the bus) at `now`.
    void accepted(std::string_view client, uint64_t now) {
        active_ = true;
        last_ = now;
        client_ = std::string(client);
    }
    // Zero and drop: no stream, no commanding client (the last command's time stays).
    void drop() {
        active_ = false;
        client_.clear();
    }
    bool active() const { return active_; }
    const std::string& client() const { return client_; }
    uint64_t last_command_at() const { return last_; }

private:
    bool active_ = false;
    uint64_t last_ = 0;
    std::string client_;
};

} // namespace caracara
