#include "drivers/platform/io_error.hpp"
#include "drivers/protocol/sim_protocol.hpp"

#include "tests/catch.hpp"
#include <cerrno>
#include <linux/i2c-dev.h>
#include <linux/spi/spidev.h>

using namespace caracara;
using namespace caracara::simproto;

TEST_CASE("writer and reader round-trip little-endian fields") {
    uint8_t buf[64];
    Writer w(buf);
    w.header(Op::I2cRdwr, 7);
    w.u16(0x1234);
    w.u32(0xdeadbeef);
    w.str("/dev/i2c-1");
    REQUIRE(w.ok());
    CHECK(buf[12] == 0x34);
    CHECK(buf[13] == 0x12);
    Reader r({buf, w.size()});
    Header h;
    REQUIRE(r.header(h));
    CHECK(h.op == uint16_t(Op::I2cRdwr));
    CHECK(h.seq == 7);
    CHECK(r.u16() == 0x1234);
    CHECK(r.u32() == 0xdeadbeef);
    CHECK(r.str(64) == "/dev/i2c-1");
    CHECK(r.at_end());
}

TEST_CASE("writer refuses to overflow and reader refuses to overrun") {
    uint8_t buf[4];
    Writer w(buf);
    w.u32(1);
    CHECK(w.ok());
    w.u8(2);
    CHECK_FALSE(w.ok());
    Reader r({buf, 3});
    r.u32();
    CHECK_FALSE(r.ok());
    uint8_t s[] = {200, 0, 0, 0, 'a'};
    Reader r2({s, sizeof s});
    CHECK(r2.str(64).empty());
    CHECK_FALSE(r2.ok());
}

TEST_CASE("ioctl argument table matches the kernel's encoding") {
    CHECK(classify_ioctl(I2C_FUNCS).kind == ArgKind::PtrOut);
    CHECK(classify_ioctl(I2C_TIMEOUT).kind == ArgKind::Value);
    CHECK(classify_ioctl(SPI_IOC_WR_MODE).kind == ArgKind::PtrIn);
    CHECK(classify_ioctl(SPI_IOC_WR_MODE).size == 1);
    CHECK(classify_ioctl(SPI_IOC_WR_MAX_SPEED_HZ).size == 4);
    CHECK(classify_ioctl(0x1234).kind == ArgKind::Unknown);
}

TEST_CASE("errno maps to typed I2C errors as the Linux bus drivers report them") {
    CHECK(io_error_from_errno(EREMOTEIO) == IoError::Nack);
    CHECK(io_error_from_errno(ENXIO) == IoError::Nack);
    CHECK(io_error_from_errno(ETIMEDOUT) == IoError::Timeout);
    CHECK(io_error_from_errno(EIO) == IoError::ClockStretch);
    CHECK(io_error_from_errno(EAGAIN) == IoError::Arbitration);
    CHECK(io_error_from_errno(ENODEV) == IoError::NoDevice);
    CHECK(errno_name(ETIMEDOUT).rfind("ETIMEDOUT", 0) == 0);
}
