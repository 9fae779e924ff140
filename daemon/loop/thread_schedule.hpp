// The daemon's real-time scheduling ([realtime], docs/realtime.md): the calling thread's policy
// and priority, and the process's memory locked. Threads inherit the policy of the thread that
// makes them (std::thread leaves PTHREAD_INHERIT_SCHED), so the loop thread takes each worker's
// schedule just before starting it and its own at the end; the workers need not know.
// Where the kernel refuses (no RLIMIT_RTPRIO, a container), one warning and the normal policy:
// the daemon runs, only less shielded from other load.
#pragma once

#include "core/config.hpp"

#include <string>

namespace caracara {

class ThreadSchedule {
public:
    explicit ThreadSchedule(const RealtimeSettings& settings) : settings_(settings) {}

    // The calling thread at the configured policy and `priority` (realtime.enabled), else at
    // the normal policy. The first refusal is logged and every later call is the normal policy.
    void realtime(uint32_t priority);
    // The calling thread at the normal policy (work that can wait: the dive writer).
    void normal();
    bool refused() const { return refused_; }

    // mlockall(MCL_CURRENT | MCL_FUTURE), the main stack faulted in, and malloc kept from
    // giving memory back; "" or why not (logged by the caller as a warning).
    static std::string lock_memory();

private:
    const RealtimeSettings& settings_;
    bool refused_ = false;
};

} // namespace caracara
