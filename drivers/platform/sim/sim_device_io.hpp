// DeviceIo that hands each open/ioctl/close to caracara-sim over its Unix socket and copies
// the replies and errno back exactly as the kernel would. No allocation per call. When the
// simulator goes away every call fails with ENODEV (the adapter is gone); the next open or
// line request connects again, so a restarted simulator is picked up by whoever reopens.
#pragma once

#include "drivers/platform/device_io.hpp"
#include "drivers/protocol/sim_protocol.hpp"

#include <array>
#include <cstdint>
#include <string>

namespace caracara {

class SimDeviceIo final : public DeviceIo {
public:
    SimDeviceIo() = default;
    ~SimDeviceIo() override;
    SimDeviceIo(const SimDeviceIo&) = delete;
    SimDeviceIo& operator=(const SimDeviceIo&) = delete;

    int connect(const std::string& socket_path); // -errno on failure
    int open(const char* path, int flags) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    int close(int fd) override;
    int write(int fd, const void* buf, size_t len) override;

    // GPIO lines of the simulated vehicle (see GpioBackend); results as the ops above.
    int gpio_request(const std::string& chip, const std::string& name, int offset, simproto::GpioMode mode,
                     bool active_low, int initial);
    int gpio_get(int line);
    int gpio_set(int line, int value);
    int gpio_release(int line);
    // GpioSet from a fatal-signal handler: one send of a message built on the stack, then a
    // bounded wait (50 ms) for its reply, sequence number 0 (roundtrip() skips it if it gets it).
    bool gpio_set_in_signal_handler(int line, int value) noexcept;
    const std::string& socket_path() const { return path_; }

private:
    // Sends tx_[0..len) and waits for the matching reply in rx_; returns the reply's result
    // and leaves `payload` positioned after it.
    int roundtrip(size_t len, simproto::Op op, simproto::Reader& payload);
    int i2c_rdwr(int fd, void* arg);
    int spi_message(int fd, unsigned long request, void* arg);
    int small_ioctl(int fd, unsigned long request, void* arg);

    int simple(simproto::Op op, int32_t a, int32_t b = -1); // ops carrying one or two i32
    void drop_connection();
    int reconnect_if_gone(); // 0 or -ENODEV
    // Handles carry the connection they were made on (the bits from kGenerationShift up), so
    // one made before the simulator restarted is refused, never taken for a new handle that
    // happens to have the same number (another line, another device).
    static constexpr int kGenerationShift = 20;
    static constexpr int kMaxGeneration = 1000;
    int wire_handle(int fd) const; // the simulator's handle, or -1 if stale
    int tagged(int handle) const;
    int generation_ = 1;
    int sock_ = -1;
    std::string path_;
    uint32_t seq_ = 0;
    size_t rx_len_ = 0;
    std::array<uint8_t, simproto::kMaxMessage> tx_{};
    std::array<uint8_t, simproto::kMaxMessage> rx_{};
};

} // namespace caracara
