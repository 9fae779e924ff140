// The device seam against the real simulator: the i2c-dev marshalling code, the errno the
// kernel would return, and the simulator's robustness against bad input.
#include "i2c_dev.hpp"
#include "sim_device_io.hpp"
#include "sim_fixture.hpp"
#include "sim_protocol.hpp"

#include <catch2/catch.hpp>
#include <cerrno>
#include <fcntl.h>
#include <linux/i2c-dev.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

using namespace caracara;
using caracara::test::SimFixture;

TEST_CASE("i2c-dev open checks I2C_FUNCS and unknown nodes fail like the kernel") {
    SimFixture f;
    SimDeviceIo io;
    REQUIRE(io.connect(f.socket()) == 0);
    I2cDev good(io, "/dev/i2c-1");
    CHECK(good.open() == 0);
    I2cDev missing(io, "/dev/i2c-7");
    CHECK(missing.open() == -ENOENT);
    unsigned long funcs = 0;
    int fd = io.open("/dev/i2c-1", O_RDWR);
    REQUIRE(fd >= 0);
    CHECK(io.ioctl(fd, I2C_FUNCS, &funcs) == 0);
    CHECK((funcs & I2C_FUNC_I2C) != 0);
    CHECK(io.ioctl(fd, 0x12345678, nullptr) == -ENOTTY); // unknown ioctl
    CHECK(io.ioctl(fd + 100, I2C_FUNCS, &funcs) == -EBADF);
    CHECK(io.close(fd) == 0);
    CHECK(io.close(fd) == -EBADF);
}

TEST_CASE("a raw order reaches the thruster byte for byte, a NACK comes back as EREMOTEIO") {
    SimFixture f;
    SimDeviceIo io;
    REQUIRE(io.connect(f.socket()) == 0);
    I2cDev bus(io, "/dev/i2c-1");
    REQUIRE(bus.open() == 0);
    // Thruster 0 is MT 0x52 -> 7-bit 0x29. Order SPEED 0xE6, INFO 100: CSUM 0x52+0xE6+0x64 = 0x19C -> 0x9C.
    const uint8_t order[] = {0xE6, 0x64, 0x9C};
    CHECK(bus.write(0x29, order) == IoError::None);
    CHECK(f.thruster_bytes(0, "LastOrder") == std::vector<uint8_t>{0xE6, 0x64, 0x9C});
    CHECK(f.thruster_byte(0, "OrderedSpeed") == 0xE6);
    // A bad checksum is discarded by the thruster (IDS 6.6.1).
    const uint8_t bad[] = {0x81, 0x64, 0x00};
    CHECK(bus.write(0x29, bad) == IoError::None);
    CHECK(f.thruster_byte(0, "OrderedSpeed") == 0xE6);
    CHECK(f.thruster_u64(0, "OrdersRejected") == 1);
    // Nobody at 0x10.
    CHECK(bus.write(0x10, order) == IoError::Nack);
    CHECK(bus.last_errno() == EREMOTEIO);
    // Injected NACK on thruster 1 (MT 0x56 -> 0x2B).
    CHECK(f.call(f.thruster_path(1), "org.caracara.Simulator1.Thruster", "SetNack", "b", 1) == "");
    CHECK(bus.write(0x2B, order) == IoError::Nack);
    auto log = f.wire_log();
    REQUIRE(log.size() >= 4);
    CHECK(log.back().addr == 0x2B);
    CHECK(log.back().result == "nack");
}

TEST_CASE("wire time is accounted at the configured clock") {
    SimFixture f;
    SimDeviceIo io;
    REQUIRE(io.connect(f.socket()) == 0);
    I2cDev bus(io, "/dev/i2c-1");
    REQUIRE(bus.open() == 0);
    const uint8_t order[] = {0x80, 0x64, static_cast<uint8_t>(0x52 + 0x80 + 0x64)};
    REQUIRE(bus.write(0x29, order) == IoError::None);
    // START + 4 bytes x 9 bits + STOP = 38 bit times of 10 us at 100 kHz.
    uint64_t wire = 0;
    sd_bus_error e = SD_BUS_ERROR_NULL;
    REQUIRE(sd_bus_get_property_trivial(f.bus(), "org.caracara.Simulator1", "/org/caracara/Simulator1",
                                        "org.caracara.Simulator1", "WireTimeNs", &e, 't', &wire) >= 0);
    CHECK(wire == 38 * 10000);
}

TEST_CASE("realistic timing really waits the wire time") {
    SimFixture f({"--realistic-timing"});
    SimDeviceIo io;
    REQUIRE(io.connect(f.socket()) == 0);
    I2cDev bus(io, "/dev/i2c-1");
    REQUIRE(bus.open() == 0);
    const uint8_t order[] = {0x80, 0x64, static_cast<uint8_t>(0x52 + 0x80 + 0x64)};
    timespec a{}, b{};
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (int i = 0; i < 20; ++i)
        REQUIRE(bus.write(0x29, order) == IoError::None);
    clock_gettime(CLOCK_MONOTONIC, &b);
    const double elapsed_us = static_cast<double>(b.tv_sec - a.tv_sec) * 1e6 + static_cast<double>(b.tv_nsec - a.tv_nsec) / 1e3;
    // 20 transactions of 380 us each cannot complete sooner than 7.6 ms of wire time.
    CHECK(elapsed_us >= 20 * 380);
    // And the wire log is stamped one transaction apart at least.
    auto log = f.wire_log();
    REQUIRE(log.size() == 20);
    for (size_t i = 1; i < log.size(); ++i)
        CHECK(log[i].time_ns - log[i - 1].time_ns >= 380000);
}

namespace {
int raw_connect(const std::string& path) {
    int s = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
    timeval tv{2, 0};
    setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    REQUIRE(connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0);
    return s;
}
int32_t reply_result(int s) {
    uint8_t buf[256];
    ssize_t n = recv(s, buf, sizeof buf, 0);
    REQUIRE(n >= 16);
    simproto::Reader r({buf, static_cast<size_t>(n)});
    simproto::Header h;
    REQUIRE(r.header(h));
    return r.i32();
}
} // namespace

TEST_CASE("malformed requests get an error reply and the simulator keeps serving") {
    SimFixture f;
    int s = raw_connect(f.socket());
    uint8_t buf[64];
    // Good header, truncated Open body.
    simproto::Writer w(buf);
    w.header(simproto::Op::Open, 1);
    w.u32(1000); // claims a 1000-byte path that is not there
    REQUIRE(send(s, buf, w.size(), 0) == static_cast<ssize_t>(w.size()));
    CHECK(reply_result(s) == -EBADMSG);
    // Unknown op.
    simproto::Writer w2(buf);
    w2.header(static_cast<simproto::Op>(99), 2);
    REQUIRE(send(s, buf, w2.size(), 0) > 0);
    CHECK(reply_result(s) == -EBADMSG);
    // I2C_RDWR with 50 messages (the kernel's limit is 42) on a handle that does not exist.
    simproto::Writer w3(buf);
    w3.header(simproto::Op::I2cRdwr, 3);
    w3.i32(3);
    w3.u32(50);
    REQUIRE(send(s, buf, w3.size(), 0) > 0);
    CHECK(reply_result(s) == -EBADF);
    // Garbage.
    const char junk[] = "hello simulator";
    REQUIRE(send(s, junk, sizeof junk, 0) > 0);
    CHECK(reply_result(s) == -EBADMSG);
    close(s);
    // Still alive and serving.
    SimDeviceIo io;
    REQUIRE(io.connect(f.socket()) == 0);
    I2cDev bus(io, "/dev/i2c-1");
    CHECK(bus.open() == 0);
    CHECK(f.sim.running());
}
