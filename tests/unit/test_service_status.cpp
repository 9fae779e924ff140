// daemon/ServiceStatus: what systemd reads from caracarad, received on a notify socket of the
// test's own (NOTIFY_SOCKET, as systemd hands it over), the daemon on the fakes of the device
// seam (DaemonRig): the STATUS= line on a change of state, READY=1 and STOPPING=1 with theirs,
// and the watchdog fed only when systemd asked for one (WATCHDOG_USEC).
#include "daemon/service_status.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

// A notify socket, named in NOTIFY_SOCKET while it lives.
class NotifySocket {
public:
    NotifySocket() {
        char tmpl[] = "/tmp/caracara-notify-XXXXXX";
        if (!mkdtemp(tmpl))
            throw std::runtime_error("mkdtemp");
        dir_ = tmpl;
        fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        const std::string path = dir_ + "/notify";
        path.copy(a.sun_path, sizeof a.sun_path - 1);
        if (fd_ < 0 || bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) < 0)
            throw std::runtime_error("cannot bind the notify socket");
        setenv("NOTIFY_SOCKET", path.c_str(), 1);
    }
    ~NotifySocket() {
        unsetenv("NOTIFY_SOCKET");
        close(fd_);
        std::error_code ignored;
        std::filesystem::remove_all(dir_, ignored);
    }
    // Every message received since the last call.
    std::vector<std::string> take() {
        std::vector<std::string> out;
        char buf[4096];
        for (ssize_t n; (n = recv(fd_, buf, sizeof buf, 0)) > 0;)
            out.emplace_back(buf, static_cast<std::size_t>(n));
        return out;
    }

private:
    std::string dir_;
    int fd_ = -1;
};

bool has(const std::vector<std::string>& messages, const std::string& text) {
    for (const std::string& m : messages)
        if (m.find(text) != std::string::npos)
            return true;
    return false;
}

} // namespace

TEST_CASE("ServiceStatus: a change of state shows on the STATUS= line; READY=1 and STOPPING=1 with theirs") {
    NotifySocket notify;
    DaemonRig rig;
    rig.run_until_ready();
    rig.daemon().status().ready("org.caracara.Vehicle1");
    auto m = notify.take();
    CHECK(has(m, "READY=1\nSTATUS=Thrusters zeroed; ready; serving org.caracara.Vehicle1"));

    REQUIRE(rig.vehicle().kill(KillSource::DBus, "test").ok());
    std::vector<std::string> seen;
    REQUIRE(rig.run_until([&] {
        for (std::string& s : notify.take())
            seen.push_back(std::move(s));
        return has(seen, "STATUS=killed by dbus");
    }));
    CHECK(has(seen, "STATUS=killed by dbus; profile water; I2C bus ok; 8 thrusters"));

    rig.daemon().status().stopping();
    CHECK(has(notify.take(), "STOPPING=1\nSTATUS=Thrusters zeroed; stopped"));
}

TEST_CASE("ServiceStatus: the watchdog is fed while the loop runs, and only when systemd asked for one") {
    NotifySocket notify;
    {
        DaemonRig rig;
        unsetenv("WATCHDOG_USEC");
        rig.daemon().status().start_watchdog();
        rig.run_for(200);
        CHECK_FALSE(has(notify.take(), "WATCHDOG=1"));
    }
    DaemonRig rig;
    // As systemd sets them for WatchdogSec= (100 ms: fed every 50 ms).
    setenv("WATCHDOG_USEC", "100000", 1);
    setenv("WATCHDOG_PID", std::to_string(getpid()).c_str(), 1);
    rig.daemon().status().start_watchdog();
    unsetenv("WATCHDOG_USEC");
    unsetenv("WATCHDOG_PID");
    std::vector<std::string> seen;
    CHECK(rig.run_until([&] {
        for (std::string& s : notify.take())
            if (s.find("WATCHDOG=1") != std::string::npos)
                seen.push_back(std::move(s));
        return seen.size() >= 3;
    }));
}
