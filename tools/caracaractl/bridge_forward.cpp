#include "tools/caracaractl/bridge_forward.hpp"

#include "tools/caracaractl/forward_relay.hpp"
#include "tools/client/client.hpp"
#include "tools/client/ssh_stderr.hpp"
#include "tools/client/ssh_target.hpp"

#include <cerrno>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <sys/wait.h>
#include <unistd.h>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

namespace {

constexpr const char* kDefaultSocket = "/run/caracara-bridge/bridge.sock";
constexpr uint16_t kDefaultPort = 8765; // Foxglove's default for a WebSocket connection

[[noreturn]] void usage(const std::string& m) { throw Failure{kExitUsage, m}; }

// A directory of the pilot's alone (0700) for ssh's end of the forward: in $XDG_RUNTIME_DIR
// (itself 0700) when there is one, else /tmp; removed with what is in it when the forward ends.
class PrivateDir {
public:
    PrivateDir() {
        const char* runtime = std::getenv("XDG_RUNTIME_DIR");
        std::string tmpl = std::string(runtime && *runtime && ::access(runtime, W_OK) == 0 ? runtime : "/tmp") +
                           "/caracaractl-bridge.XXXXXX";
        if (!::mkdtemp(tmpl.data()))
            throw Failure{kExitUnavailable, "mkdtemp " + tmpl + ": " + std::strerror(errno)};
        path_ = tmpl;
    }
    ~PrivateDir() {
        ::unlink(socket().c_str());
        ::rmdir(path_.c_str());
    }
    PrivateDir(const PrivateDir&) = delete;
    PrivateDir& operator=(const PrivateDir&) = delete;
    std::string socket() const { return path_ + "/bridge.sock"; }

private:
    std::string path_;
};

// ssh's exit: 255 is its own failure (not reached, refused), anything else the forward's end.
int exit_of(int status) {
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
        return kExitOk;
    return kExitUnavailable;
}

} // namespace

const char* bridge_forward_help() {
    return "\nFoxglove and the cockpit (caracara-bridge on the vehicle, docs/foxglove.md, docs/cockpit.md):\n"
           "  -H [USER@]HOST[:PORT] bridge [--port N] [--socket PATH] [--ssh-config FILE]\n"
           "                                   Forward the vehicle's bridge socket to localhost:N\n"
           "                                   (default 8765) with ssh -L and print the addresses to\n"
           "                                   open in Foxglove (ws://) and in a browser (http://,\n"
           "                                   the cockpit), with this session's key (?key=): the port\n"
           "                                   refuses requests without it (403); held until ^C\n";
}

int run_bridge_forward(const caracara::dbus::BusChoice& choice, const std::vector<std::string>& args) {
    uint16_t port = kDefaultPort;
    std::string socket_path = kDefaultSocket, ssh_config;
    for (std::size_t i = 0; i < args.size(); ++i) {
        auto value = [&](const char* opt) {
            if (i + 1 >= args.size())
                usage(std::string(opt) + " needs a value");
            return args[++i];
        };
        if (args[i] == "--port") {
            const std::string p = value("--port");
            const auto [end, ec] = std::from_chars(p.data(), p.data() + p.size(), port);
            if (ec != std::errc() || end != p.data() + p.size() || port == 0)
                usage("--port needs a port number 1..65535, not '" + p + "'");
        } else if (args[i] == "--socket") {
            socket_path = value("--socket");
            if (socket_path.empty() || socket_path[0] != '/')
                usage("--socket needs an absolute path");
        } else if (args[i] == "--ssh-config") {
            ssh_config = value("--ssh-config");
        } else {
            usage("unknown argument '" + args[i] + "' for bridge");
        }
    }
    if (choice.kind != caracara::dbus::BusChoice::Kind::Remote)
        usage("bridge forwards from the vehicle: give it with -H [USER@]HOST[:PORT]");
    const auto target = parse_ssh_target(choice.address);
    if (!target)
        usage("-H needs [USER@]HOST[:PORT], not '" + choice.address + "'");
    // The port is caracaractl's own (bound now: in use is said before ssh runs); ssh's end is a
    // socket in a directory no other local user can enter, and only requests with the key go on.
    const PrivateDir dir;
    const ForwardKey key = ForwardKey::random(port);
    ForwardRelay relay(port, dir.socket(), key);

    std::vector<std::string> argv = {"ssh", "-N", "-T", "-x", "-o", "ExitOnForwardFailure=yes"};
    if (!ssh_config.empty())
        argv.insert(argv.end(), {"-F", ssh_config});
    if (!target->port.empty())
        argv.insert(argv.end(), {"-p", target->port});
    argv.insert(argv.end(), {"-L", dir.socket() + ":" + socket_path, "--", target->destination()});

    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    sigaddset(&mask, SIGCHLD);
    sigset_t old;
    sigprocmask(SIG_BLOCK, &mask, &old);
    // ssh's words are copied through and kept: they tell a refused login (4) from a host not
    // reached (3), as for every -H command (ssh exits 255 for both).
    SshStderr ssh_stderr;
    (void)ssh_stderr.capture(); // if it cannot, ssh writes to our stderr and a failure counts as 3
    const pid_t pid = ::fork();
    if (pid == 0) {
        sigprocmask(SIG_SETMASK, &old, nullptr);
        std::vector<char*> cargv;
        for (std::string& a : argv)
            cargv.push_back(a.data());
        cargv.push_back(nullptr);
        ::execvp("ssh", cargv.data());
        std::fprintf(stderr, "caracaractl: cannot run ssh: %s\n", std::strerror(errno));
        ::_exit(127);
    }
    ssh_stderr.restore();
    if (pid < 0)
        throw Failure{kExitUnavailable, std::string("fork: ") + std::strerror(errno)};

    bool announced = false;
    for (;;) {
        int status = 0;
        if (::waitpid(pid, &status, WNOHANG) == pid) {
            if ((!announced || exit_of(status) != kExitOk) && SshStderr::refused(ssh_stderr.said(std::chrono::seconds(2))))
                throw Failure{kExitDenied, "SSH refused the login to " + choice.address};
            if (!announced || exit_of(status) != kExitOk)
                throw Failure{kExitUnavailable, "ssh to " + choice.address + " ended (status " +
                                                    std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : 255) +
                                                    "); the forward is gone"};
            return kExitOk;
        }
        if (!announced && ::access(dir.socket().c_str(), F_OK) == 0) {
            announced = true;
            // The Foxglove address, then the cockpit's (the same socket serves both, docs/cockpit.md),
            // each with the session's key; a browser trades it for a cookie on its first load.
            std::printf("ws://localhost:%u/?key=%s\nhttp://localhost:%u/?key=%s\n", port, key.key().c_str(), port,
                        key.key().c_str());
            std::fflush(stdout);
            std::fprintf(stderr, "caracaractl: open the ws:// address in Foxglove (Open connection, Foxglove "
                                 "WebSocket), or the http:// one, the cockpit, in a browser; they carry this "
                                 "session's key (no other user of this computer has it). Ctrl-C ends the forward\n");
        }
        relay.run_once(50, announced);
        const timespec now{0, 0};
        const int sig = sigtimedwait(&mask, nullptr, &now);
        if (sig == SIGINT || sig == SIGTERM) {
            ::kill(pid, SIGTERM);
            ::waitpid(pid, &status, 0);
            return kExitOk;
        }
    }
}

} // namespace caracara::ctl
