// A line or a device lost while the Vehicle carries out a safety action (SafetyLines tells it
// from inside the sequence, e.g. the kill output failing as it is asserted) is killed for once
// that sequence is done, not inside it: the sequence is not re-entered halfway.
#pragma once

#include <string>
#include <string_view>
#include <utility>

namespace caracara {

class DeviceLossDeferral final {
public:
    // Runs `sequence` with losses deferred.
    template <class F>
    void during(F&& sequence) {
        in_sequence_ = true;
        std::forward<F>(sequence)();
        in_sequence_ = false;
    }
    // Inside a sequence: `why` kept for after it (true); outside: false, the caller kills now.
    bool defer(std::string_view why) {
        if (in_sequence_)
            lost_ = why;
        return in_sequence_;
    }
    // The loss deferred by the last sequence, if any ("" otherwise), and forgotten.
    std::string take() { return std::exchange(lost_, {}); }

private:
    bool in_sequence_ = false;
    std::string lost_;
};

} // namespace caracara
