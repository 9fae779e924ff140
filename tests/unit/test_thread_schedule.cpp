// daemon/loop/ThreadSchedule, judged from the kernel's side (the calling thread's policy and
// priority, as /proc/<pid>/task/<tid>/stat shows them): at the configured policy and priority
// when the kernel allows it; where it refuses, one warning naming the policy as [realtime]
// spells it, the priority, the errno and RLIMIT_RTPRIO, and every later call at the normal
// policy without another line; realtime.enabled = false, the normal policy; memory not locked
// where RLIMIT_MEMLOCK would make an allocation past it fail, with the reason.
#include "daemon/loop/thread_schedule.hpp"

#include "tests/catch.hpp"
#include "tests/unit/fakes/stderr_lines.hpp"

#include <fstream>
#include <functional>
#include <linux/capability.h>
#include <pthread.h>
#include <sched.h>
#include <stdexcept>
#include <string>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <thread>
#include <unistd.h>
#include <vector>

using namespace caracara;
using namespace caracara::test;

namespace {

struct Schedule {
    int policy = -1;
    int priority = -1;
    bool operator==(const Schedule&) const = default;
};

Schedule current() {
    Schedule s;
    sched_param sp{};
    pthread_getschedparam(pthread_self(), &s.policy, &sp);
    s.priority = sp.sched_priority;
    return s;
}

// The calling thread's effective capability `cap` dropped (capabilities are per thread; the
// permitted set keeps it, and it is given back when this goes).
class DroppedCapability {
public:
    explicit DroppedCapability(int cap) : cap_(cap) { set(false); }
    ~DroppedCapability() { set(true); }

private:
    void set(bool on) {
        __user_cap_header_struct h{_LINUX_CAPABILITY_VERSION_3, 0};
        __user_cap_data_struct d[2]{};
        if (::syscall(SYS_capget, &h, d) != 0)
            throw std::runtime_error("capget");
        auto& word = d[cap_ / 32].effective;
        const unsigned bit = 1u << (cap_ % 32);
        if (on)
            word |= bit & d[cap_ / 32].permitted;
        else
            word &= ~bit;
        if (::syscall(SYS_capset, &h, d) != 0)
            throw std::runtime_error("capset");
    }
    int cap_;
};

// A resource limit's soft value lowered while it lives.
class LoweredLimit {
public:
    LoweredLimit(int resource, rlim_t soft) : resource_(resource) {
        getrlimit(resource_, &saved_);
        rlimit l = saved_;
        l.rlim_cur = soft;
        if (setrlimit(resource_, &l) != 0)
            throw std::runtime_error("setrlimit");
    }
    ~LoweredLimit() { setrlimit(resource_, &saved_); }

private:
    int resource_;
    rlimit saved_{};
};

// Runs `f` on a thread of its own (the test runner's own thread keeps its schedule).
void on_thread(const std::function<void()>& f) {
    std::thread t(f);
    t.join();
}

// Whether the kernel lets this thread take a real-time policy at `priority`.
bool kernel_allows(int priority) {
    sched_param sp{};
    sp.sched_priority = priority;
    if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) != 0)
        return false;
    sp.sched_priority = 0;
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
    return true;
}

RealtimeSettings settings(SchedPolicy policy, bool enabled = true) {
    RealtimeSettings s;
    s.enabled = enabled;
    s.policy = policy;
    return s;
}

} // namespace

TEST_CASE("ThreadSchedule: refused by the kernel, one warning naming policy, priority, errno and limit; then normal") {
    for (const SchedPolicy policy : {SchedPolicy::Fifo, SchedPolicy::RoundRobin}) {
        INFO(name_of(policy));
        const RealtimeSettings rt = settings(policy);
        ThreadSchedule schedule(rt);
        // A thread without CAP_SYS_NICE under RLIMIT_RTPRIO 0: caracarad in a container.
        const LoweredLimit rtprio(RLIMIT_RTPRIO, 0);
        on_thread([&] {
            const DroppedCapability nice(CAP_SYS_NICE);
            const auto first = stderr_lines([&] { schedule.realtime(40); });
            CHECK(schedule.refused());
            CHECK(current() == Schedule{SCHED_OTHER, 0});
            REQUIRE(first.size() == 1);
            const std::string& l = first[0];
            CHECK(l.rfind("<4>realtime: the kernel refused policy " + std::string(name_of(policy)) + " at priority 40 (EPERM", 0) == 0);
            CHECK(l.find("RLIMIT_RTPRIO 0") != std::string::npos);
            CHECK(l.find("every thread runs at the normal policy") != std::string::npos);
            // Every later call: the normal policy, said no more.
            const auto later = stderr_lines([&] { schedule.realtime(38); });
            CHECK(later.empty());
            CHECK(current() == Schedule{SCHED_OTHER, 0});
        });
    }
}

TEST_CASE("ThreadSchedule: allowed, the thread at the configured policy and priority; normal() takes it back") {
    for (const SchedPolicy policy : {SchedPolicy::Fifo, SchedPolicy::RoundRobin}) {
        INFO(name_of(policy));
        const RealtimeSettings rt = settings(policy);
        on_thread([&] {
            ThreadSchedule schedule(rt);
            const bool allowed = kernel_allows(40);
            const auto lines = stderr_lines([&] { schedule.realtime(40); });
            if (allowed) {
                CHECK_FALSE(schedule.refused());
                CHECK(lines.empty());
                CHECK(current() == Schedule{policy == SchedPolicy::Fifo ? SCHED_FIFO : SCHED_RR, 40});
                schedule.normal();
                CHECK(current() == Schedule{SCHED_OTHER, 0});
            } else {
                // Where this machine refuses, the refusal is what the daemon must do.
                CHECK(schedule.refused());
                CHECK(lines.size() == 1);
                CHECK(current() == Schedule{SCHED_OTHER, 0});
            }
        });
    }
}

TEST_CASE("ThreadSchedule: realtime.enabled = false, the normal policy even for a thread that was real-time") {
    const RealtimeSettings rt = settings(SchedPolicy::Fifo, false);
    on_thread([&] {
        ThreadSchedule schedule(rt);
        sched_param sp{};
        sp.sched_priority = 10;
        // Real-time first where the kernel allows it: normal() must take it back.
        (void)pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
        const auto lines = stderr_lines([&] { schedule.realtime(40); });
        CHECK(lines.empty());
        CHECK_FALSE(schedule.refused());
        CHECK(current() == Schedule{SCHED_OTHER, 0});
    });
}

TEST_CASE("ThreadSchedule: memory is not locked under a limit an allocation would run into; the reason given") {
    // The process without CAP_IPC_LOCK (the main thread's, as /proc/self/status shows) under a
    // 64 KiB RLIMIT_MEMLOCK: mlockall(MCL_FUTURE) would make every allocation past it fail.
    const DroppedCapability lock(CAP_IPC_LOCK);
    const LoweredLimit memlock(RLIMIT_MEMLOCK, 64 * 1024);
    const std::string why = ThreadSchedule::lock_memory();
#if CARACARA_TEST_ASAN
    CHECK(why.find("AddressSanitizer") != std::string::npos);
#else
    CHECK(why == "RLIMIT_MEMLOCK is 64 kB, not unlimited (caracarad.service's LimitMEMLOCK=infinity): past it every "
                 "allocation would fail");
#endif
    // Nothing was locked.
    std::ifstream status("/proc/self/status");
    std::string line;
    bool seen = false;
    while (std::getline(status, line))
        if (line.rfind("VmLck:", 0) == 0) {
            seen = true;
            CHECK(std::stoul(line.substr(6)) == 0);
        }
    CHECK(seen);
}
