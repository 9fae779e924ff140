#include "core/recovery_policy.hpp"

#include <algorithm>

namespace caracara {

RecoveryPolicy::Failure RecoveryPolicy::failed() const {
    Failure f;
    f.lost = attempt_ == attempts_;
    f.retry_in_ns = kBackgroundRetryNs;
    if (attempt_ < attempts_) {
        const uint64_t backoff_ns = static_cast<uint64_t>(backoff_ms_) * 1'000'000ull;
        f.retry_in_ns = std::min<uint64_t>(backoff_ns << std::min<uint32_t>(attempt_ - 1, 16), kBackgroundRetryNs);
    }
    return f;
}

} // namespace caracara
