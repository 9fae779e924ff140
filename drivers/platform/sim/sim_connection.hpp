// The Unix socket to caracara-sim that SimDeviceIo's calls travel on: one request out, the
// reply with its sequence number back (a late reply to an abandoned request is skipped). When
// the simulator goes away every call fails with ENODEV; the next open or line request connects
// again, and the handles made on the old connection are refused from then on.
#pragma once

#include "drivers/protocol/sim_protocol.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

namespace caracara {

class SimConnection {
public:
    SimConnection() = default;
    ~SimConnection();
    SimConnection(const SimConnection&) = delete;
    SimConnection& operator=(const SimConnection&) = delete;

    int connect(const std::string& socket_path); // -errno on failure
    const std::string& socket_path() const { return path_; }
    // Connected, or connected again to a restarted simulator: 0 or -ENODEV.
    int reconnect_if_gone();

    // A request of `op` in the send buffer, its header written with the next sequence number.
    simproto::Writer request(simproto::Op op) {
        simproto::Writer w(tx_);
        w.header(op, ++seq_);
        return w;
    }
    // Sends the request (its first `len` bytes) and waits for the matching reply; returns the
    // reply's result and leaves `payload` positioned after it.
    int roundtrip(size_t len, simproto::Op op, simproto::Reader& payload);

    // Handles carry the connection they were made on (the bits from kGenerationShift up), so
    // one made before the simulator restarted is refused, never taken for a new handle that
    // happens to have the same number (another line, another device).
    int wire_handle(int fd) const; // the simulator's handle, or -1 if stale
    int tagged(int handle) const;  // a handle (or -errno) as the caller holds it

    // GpioSet from a fatal-signal handler: one send of a message built on the stack, then a
    // bounded wait (50 ms) for its reply, sequence number 0 (roundtrip() skips it if it gets it).
    bool gpio_set_in_signal_handler(int line, int value) noexcept;

private:
    void drop();

    static constexpr int kGenerationShift = 20;
    static constexpr int kMaxGeneration = 1000;
    int generation_ = 1;
    int sock_ = -1;
    std::string path_;
    uint32_t seq_ = 0;
    std::array<uint8_t, simproto::kMaxMessage> tx_{};
    std::array<uint8_t, simproto::kMaxMessage> rx_{};
};

} // namespace caracara
