// The bridge's client slots (--max-clients): a WebSocket client takes one once its request is
// read and its token checked, never before, so connections that never bring a valid request
// (stalled, tokenless) cannot lock the pilots out; those are bounded apart (BridgeServer).
#pragma once

#include <cstddef>
#include <memory>

namespace caracara::bridge {

class ClientSlots {
public:
    explicit ClientSlots(std::size_t max) : max_(max) {}

    // A slot held while the returned handle (or a copy) lives; empty when all are taken.
    std::shared_ptr<void> claim();
    std::size_t taken() const { return *taken_; }
    std::size_t max() const { return max_; }

private:
    std::size_t max_;
    std::shared_ptr<std::size_t> taken_ = std::make_shared<std::size_t>(0);
};

} // namespace caracara::bridge
