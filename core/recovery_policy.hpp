// How often and how soon to try clearing a locked I2C bus: bounded attempts with exponential
// backoff, then slow retries in the background; the bus is "lost" once the attempts are used
// up. Time is passed in.
#pragma once

#include <cstdint>

namespace caracara {

class RecoveryPolicy {
public:
    static constexpr uint64_t kBackgroundRetryNs = 5'000'000'000ull;

    RecoveryPolicy(uint32_t attempts, uint32_t backoff_ms) : attempts_(attempts), backoff_ms_(backoff_ms) {}

    void begin(uint64_t now_ns) {
        attempt_ = 0;
        started_ns_ = now_ns;
    }
    uint32_t next_attempt() { return ++attempt_; }
    uint32_t attempt() const { return attempt_; }

    struct Failure {
        bool lost = false;      // this failure used up the attempts: the bus is lost now
        uint64_t retry_in_ns = 0;
    };
    Failure failed() const;
    double elapsed_ms(uint64_t now_ns) const { return static_cast<double>(now_ns - started_ns_) / 1e6; }

private:
    uint32_t attempts_;
    uint32_t backoff_ms_;
    uint32_t attempt_ = 0;
    uint64_t started_ns_ = 0;
};

} // namespace caracara
