// The device protocol's operations (drivers/protocol/sim_protocol.hpp), one handler each in a table
// indexed by the request's op, served against the simulated vehicle: what the kernel's
// i2c-dev, spidev, sysfs and GPIO character device do with the same requests.
#pragma once

#include "drivers/protocol/sim_protocol.hpp"
#include "sim/device_session.hpp"
#include "sim/sim_vehicle.hpp"

#include <cstdint>
#include <span>

namespace caracara::sim {

class DeviceOps {
public:
    explicit DeviceOps(SimVehicle& vehicle) : vehicle_(vehicle) {}

    // Serves one request of `session` and writes its reply into `reply`; returns the reply's
    // length and, in `wire_ns`, the wire time the request occupied. Every request gets exactly
    // one reply: a malformed one -EBADMSG, one whose reply would not fit -EMSGSIZE.
    // `truncated`: the request was longer than kMaxMessage (only its start is in `req`); it is
    // refused whole with -EMSGSIZE, never served cut short.
    size_t handle(DeviceSession& session, std::span<const uint8_t> req, std::span<uint8_t> reply, uint64_t& wire_ns,
                  bool truncated = false);
    uint64_t bad_requests() const { return bad_requests_; }
    // Of the last request's wire time, how long a slave held the clock (a hung device): the
    // reply waits that long even when the wire's own timing is not simulated.
    uint64_t last_held_ns() const { return held_ns_; }
    // The last request's wire was the SPI bus's (each bus keeps its own time).
    bool last_on_spi() const { return on_spi_; }
    // A client that went away releases its GPIO lines, as the kernel does for a process.
    void release(DeviceSession& session);

private:
    struct Request;
    using Handler = uint64_t (DeviceOps::*)(Request&);
    struct Entry {
        simproto::Op op;
        Handler handler;
    };
    static const Entry kTable[];

    uint64_t open(Request& q);
    uint64_t close(Request& q);
    uint64_t i2c_rdwr(Request& q);
    uint64_t spi_message(Request& q);
    uint64_t ioctl(Request& q);
    uint64_t write(Request& q);
    uint64_t gpio_request(Request& q);
    uint64_t gpio_line_op(Request& q); // GpioGet, GpioSet, GpioRelease
    uint64_t gpio_watch(Request& q);

    SimVehicle& vehicle_;
    uint64_t bad_requests_ = 0;
    uint64_t held_ns_ = 0;
    bool on_spi_ = false;
};

} // namespace caracara::sim
