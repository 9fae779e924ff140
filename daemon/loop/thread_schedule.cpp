#include "daemon/loop/thread_schedule.hpp"

#include "daemon/loop/cold_libraries.hpp"
#include "daemon/loop/log.hpp"
#include "drivers/platform/io_error.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CARACARA_CLANG_ASAN 1
#endif
#endif

namespace caracara {

namespace {

// Locked memory is resident: each thread's whole stack counts. The workers and the dive writer
// touch 8-16 KiB of theirs (smaps of an unlocked daemon at 50 Hz with a command stream, whose
// untouched stack pages stay out); 128 KiB leaves them eight times that.
constexpr std::size_t kThreadStackBytes = 128 * 1024;

// Whether the process may lock more than RLIMIT_MEMLOCK (CAP_IPC_LOCK, bit 14 of CapEff).
// (Unused in a sanitized build, which never locks.)
[[maybe_unused]] bool may_lock_any_amount() {
    std::ifstream f("/proc/self/status");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind("CapEff:", 0) == 0)
            return (std::stoull(line.substr(7), nullptr, 16) >> 14) & 1;
    return false;
}

// The main thread's stack grows by page faults; touch what the loop will use now, while
// memory is locked, so that a deep call on the hot path does not fault. The loop touches 32 KiB
// of it at 50 Hz with a command stream (smaps of an unlocked daemon): four times that.
[[gnu::noinline, maybe_unused]] void fault_in_stack() {
    constexpr std::size_t kStackBytes = 128 * 1024;
    char buf[kStackBytes];
    std::memset(buf, 0, sizeof buf);
    asm volatile("" : : "r"(buf) : "memory"); // kept: the writes are the point
}

} // namespace

void ThreadSchedule::realtime(uint32_t priority) {
    if (!settings_.enabled || refused_) {
        normal();
        return;
    }
    sched_param sp{};
    sp.sched_priority = static_cast<int>(priority);
    const int policy = settings_.policy == SchedPolicy::Fifo ? SCHED_FIFO : SCHED_RR;
    if (int r = pthread_setschedparam(pthread_self(), policy, &sp); r != 0) {
        refused_ = true;
        rlimit rl{};
        getrlimit(RLIMIT_RTPRIO, &rl);
        // The policy as [realtime] policy spells it: one name for it wherever a user reads it.
        log_warning("realtime: the kernel refused policy %s at priority %u (%s; RLIMIT_RTPRIO %lld: caracarad.service's "
                    "LimitRTPRIO=, or a container without CAP_SYS_NICE); every thread runs at the normal policy",
                    std::string(name_of(settings_.policy)).c_str(), priority, errno_name(r).c_str(),
                    rl.rlim_cur == RLIM_INFINITY ? -1LL : static_cast<long long>(rl.rlim_cur));
        normal();
    }
}

void ThreadSchedule::normal() {
    sched_param sp{};
    int policy = SCHED_OTHER;
    if (pthread_getschedparam(pthread_self(), &policy, &sp) == 0 && policy == SCHED_OTHER)
        return;
    sp.sched_priority = 0;
    // Leaving a real-time policy is always allowed.
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &sp);
}

std::string ThreadSchedule::lock_memory() {
#if defined(__SANITIZE_ADDRESS__) || defined(CARACARA_CLANG_ASAN)
    return "built with AddressSanitizer, whose shadow memory is terabytes of address space";
#else
    rlimit rl{};
    getrlimit(RLIMIT_MEMLOCK, &rl);
    // With MCL_FUTURE a limit turns the daemon's next allocation past it into a failure;
    // better unlocked than that.
    if (rl.rlim_cur != RLIM_INFINITY && !may_lock_any_amount())
        return "RLIMIT_MEMLOCK is " + std::to_string(rl.rlim_cur / 1024) +
               " kB, not unlimited (caracarad.service's LimitMEMLOCK=infinity): past it every allocation would fail";
    // Locked memory is resident memory: the threads made from now on get 128 KiB stacks instead
    // of RLIMIT_STACK's 8 MiB, and every thread allocates from the one main heap instead of an
    // arena of its own (64 MiB of address space each, locked as it is used).
    pthread_attr_t attr;
    if (pthread_attr_init(&attr) == 0) {
        pthread_attr_setstacksize(&attr, kThreadStackBytes);
        pthread_setattr_default_np(&attr);
        pthread_attr_destroy(&attr);
    }
    mallopt(M_ARENA_MAX, 1);
    // The libraries off the hot path kept out of the lock (no other thread runs yet).
    ColdLibraries cold;
    cold.hide();
    const int locked = mlockall(MCL_CURRENT | MCL_FUTURE);
    const int error = errno;
    const std::size_t kept_out = cold.release();
    if (locked != 0)
        return std::string("mlockall: ") + errno_name(error);
    log_info("realtime: %zu KiB of libraries off the hot path left unlocked", kept_out);
    // Freed heap stays mapped (and locked) rather than being given back and faulted in again.
    mallopt(M_TRIM_THRESHOLD, -1);
    mallopt(M_MMAP_MAX, 0);
    fault_in_stack();
    return {};
#endif
}

} // namespace caracara
