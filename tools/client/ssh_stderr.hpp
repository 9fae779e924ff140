// What ssh says on its stderr while it carries caracaractl's bus connection (-H): copied through
// to caracaractl's stderr as it comes, and kept, so that a failed connection can be told apart:
// refused by SSH (exit 4) or the vehicle not reached (exit 3). ssh exits 255 for both, so its
// words are all there is to go by.
#pragma once

#include <chrono>
#include <memory>
#include <string>

namespace caracara::client {

class SshStderr {
public:
    SshStderr() = default;
    SshStderr(const SshStderr&) = delete;
    SshStderr& operator=(const SshStderr&) = delete;
    ~SshStderr();

    // Points fd 2 at a pipe, so that the next child forked (ssh, by sd_bus_open_system_remote)
    // inherits it as its stderr; returns -errno. restore() gives caracaractl its stderr back and
    // starts the copy.
    int capture();
    void restore();

    // Waits at most `timeout` for ssh to close its stderr (it has exited), then returns all it said.
    std::string said(std::chrono::milliseconds timeout);

    // "Refused" when ssh's words say the login was refused (key, user, host key, account), as
    // opposed to a host that could not be reached or a connection that dropped.
    static bool refused(const std::string& said);

private:
    struct Relay;
    std::shared_ptr<Relay> relay_; // shared with the copying thread, which may outlive this
    int saved_stderr_ = -1;
    int pipe_write_ = -1;
};

} // namespace caracara::client
