// The device seam against the real simulator: the i2c-dev marshalling code, the errno the
// kernel would return, and the simulator's robustness against bad input.
#include "drivers/platform/i2c_dev.hpp"
#include "drivers/platform/sim/sim_device_io.hpp"
#include "tests/integration/sim_fixture.hpp"
#include "drivers/protocol/sim_protocol.hpp"

#include "tests/catch.hpp"
#include <cerrno>
#include <fcntl.h>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <linux/spi/spidev.h>
#include <map>
#include <optional>
#include <random>
#include <vector>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

using namespace caracara;
using caracara::test::SimFixture;

namespace {
// A stop order (SPEED 0x80, INFO 100) for the thruster at MT 0x52 (7-bit 0x29), with the
// checksum over the address byte.
const uint8_t kOrder[] = {0x80, 0x64, static_cast<uint8_t>(0x52 + 0x80 + 0x64)};
} // namespace

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
    REQUIRE(bus.write(0x29, kOrder) == IoError::None);
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
    timespec a{}, b{};
    clock_gettime(CLOCK_MONOTONIC, &a);
    for (int i = 0; i < 20; ++i)
        REQUIRE(bus.write(0x29, kOrder) == IoError::None);
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

TEST_CASE("the wire log is read in pages, and a large log cannot take the simulator off the bus") {
    SimFixture f;
    SimDeviceIo io;
    REQUIRE(io.connect(f.socket()) == 0);
    I2cDev bus(io, "/dev/i2c-1");
    REQUIRE(bus.open() == 0);
    for (int i = 0; i < 10; ++i)
        REQUIRE(bus.write(0x29, kOrder) == IoError::None);
    const uint64_t first = f.wire_log().front().index;
    uint64_t next = 0;
    auto page = f.wire_log_page(first, 4, &next);
    REQUIRE(page.size() == 4);
    CHECK(next == page.back().index + 1);
    page = f.wire_log_page(next, 100, &next);
    CHECK(page.size() == 6);
    CHECK(page.front().index == first + 4);
    CHECK(f.wire_log_page(next, 100, &next).empty()); // the end: nothing new, next stays
    CHECK(next == page.back().index + 1);
    CHECK(f.call("/org/caracara/Simulator1", "org.caracara.Simulator1", "GetWireLogPage", "tu", uint64_t{0}, 0u) ==
          "org.caracara.Simulator1.Error.InvalidArgument");

    // 2200 messages of 8000 bytes: about 17.6 MB of log, more than one reply may carry
    // (16 MiB, half of dbus-daemon's 32 MiB message limit, whose excess ends the sender's
    // connection). GetWireLog answers with a page and where to go on; the pages hold them all.
    const std::vector<uint8_t> big(8000, 0x55);
    const uint64_t start = next;
    for (int i = 0; i < 2200; ++i)
        REQUIRE(bus.write(0x29, big) == IoError::None);
    size_t total = 0, pages = 0;
    for (uint64_t at = start;; ++pages) {
        uint64_t nx = 0;
        const auto got = f.wire_log_page(at, UINT32_MAX, &nx);
        if (got.empty())
            break;
        CHECK(got.front().index == at);
        for (const auto& e : got)
            total += e.data.size() == big.size();
        at = nx;
    }
    CHECK(total == 2200);
    CHECK(pages == 2);
    CHECK(f.wire_log(start).size() < 2200); // one page
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
// One reply for one request, within the receive timeout of raw_connect, with a reply's header:
// its result; nullopt when none came.
std::optional<int32_t> got_reply(int s) {
    uint8_t buf[simproto::kMaxMessage];
    ssize_t n = recv(s, buf, sizeof buf, 0);
    if (n < static_cast<ssize_t>(simproto::kHeaderSize + 4))
        return std::nullopt;
    simproto::Reader r({buf, static_cast<size_t>(n)});
    simproto::Header h;
    if (!r.header(h) || !(h.op & simproto::kReplyBit))
        return std::nullopt;
    return r.i32();
}
// The result of the one reply that must come.
int32_t reply_result(int s) {
    const auto result = got_reply(s);
    REQUIRE(result);
    return *result;
}
} // namespace

// A request longer than the protocol's kMaxMessage is refused whole with EMSGSIZE, never read
// cut short (SEQPACKET would drop its tail silently) and served.
TEST_CASE("a request longer than the protocol allows is refused with EMSGSIZE") {
    SimFixture f;
    int s = raw_connect(f.socket());
    uint8_t open_req[64];
    simproto::Writer open(open_req);
    open.header(simproto::Op::Open, 1);
    open.str("/dev/i2c-1");
    open.i32(O_RDWR);
    REQUIRE(send(s, open_req, open.size(), 0) == static_cast<ssize_t>(open.size()));
    REQUIRE(reply_result(s) == 3);
    const uint64_t bad_before = f.root_u64("BadRequests");
    const uint32_t big = static_cast<uint32_t>(simproto::kMaxMessage) + 100;
    std::vector<uint8_t> buf(simproto::kMaxMessage + 1000);
    simproto::Writer w(buf);
    w.header(simproto::Op::Write, 4);
    w.i32(3);
    w.u32(big);
    std::vector<uint8_t> junk(big, 'x');
    w.bytes(junk.data(), junk.size());
    REQUIRE(w.ok());
    REQUIRE(send(s, buf.data(), w.size(), 0) == static_cast<ssize_t>(w.size()));
    CHECK(reply_result(s) == -EMSGSIZE);
    CHECK(f.root_u64("BadRequests") == bad_before + 1);
    // Still serving, on this connection and a new one.
    REQUIRE(send(s, open_req, open.size(), 0) == static_cast<ssize_t>(open.size()));
    CHECK(reply_result(s) == 4);
    close(s);
    CHECK(f.sim.running());
}

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

TEST_CASE("a reply longer than the protocol allows is an error, not a silent truncation") {
    SimFixture f;
    int s = raw_connect(f.socket());
    std::vector<uint8_t> buf(512);
    simproto::Writer open(buf);
    open.header(simproto::Op::Open, 1);
    open.str("/dev/i2c-1");
    open.i32(O_RDWR);
    REQUIRE(send(s, buf.data(), open.size(), 0) > 0);
    const int32_t handle = reply_result(s);
    REQUIRE(handle >= 0);
    // Nine read messages of 8192 bytes: 72 KiB of read data, more than one reply can carry.
    simproto::Writer w(buf);
    w.header(simproto::Op::I2cRdwr, 2);
    w.i32(handle);
    w.u32(9);
    for (int i = 0; i < 9; ++i) {
        w.u16(0x29);
        w.u16(I2C_M_RD);
        w.u16(8192);
    }
    REQUIRE(send(s, buf.data(), w.size(), 0) > 0);
    CHECK(reply_result(s) == -EMSGSIZE);
    close(s);
    CHECK(f.sim.running());
}

namespace {
// A request of the corpus below, built with the protocol's own writer.
template <typename Fill> std::vector<uint8_t> request(simproto::Op op, uint32_t seq, Fill fill) {
    std::vector<uint8_t> buf(512);
    simproto::Writer w(buf);
    w.header(op, seq);
    fill(w);
    REQUIRE(w.ok());
    buf.resize(w.size());
    return buf;
}

} // namespace

// In the manner of a fuzzer, without one: every kind of request, valid, then mutated at random
// (bytes flipped, lengths and counts replaced by edge values, cut short, extended, another op).
// Each one must get exactly one reply, and the simulator must still serve afterwards; the
// sanitizer build of the simulator aborts on any out-of-bounds access or undefined behaviour.
TEST_CASE("mutated requests of every kind get a reply and never bring the simulator down") {
    SimFixture f;
    const unsigned seed = 20261121;
    INFO("seed " << seed);
    std::mt19937 rng(seed);
    auto pick = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
    const uint32_t edges[] = {0, 1, 2, 3, 7, 42, 43, 255, 256, 4096, 65535, 65536, 0x7fffffff, 0x80000000, 0xffffffff};

    int s = -1;
    std::vector<std::vector<uint8_t>> corpus;
    auto send_request = [&](const std::vector<uint8_t>& req) {
        REQUIRE(send(s, req.data(), req.size(), 0) == static_cast<ssize_t>(req.size()));
        return reply_result(s);
    };
    auto open = [&](const char* path) {
        return send_request(request(simproto::Op::Open, 1, [&](simproto::Writer& w) {
            w.str(path);
            w.i32(O_RDWR);
        }));
    };
    auto connect_and_open = [&] {
        if (s >= 0)
            close(s);
        s = raw_connect(f.socket());
        // Handles 3-7 on a fresh connection: the sysfs bind attribute, the I2C bus, the SPI
        // device, the sysfs unbind attribute, a GPIO line. Opened for real so that the mutations
        // reach every handler. A mutation may have unbound the I2C driver: bind it again first.
        REQUIRE(open("/sys/bus/platform/drivers/i2c-bcm2835/bind") == 3);
        const int bound = send_request(request(simproto::Op::Write, 2, [](simproto::Writer& w) {
            w.i32(3);
            w.u32(12);
            w.bytes("fe804000.i2c", 12);
        }));
        REQUIRE((bound == 12 || bound == -EBUSY));
        int i2c = -ENOENT;
        for (int tries = 0; tries < 500 && i2c == -ENOENT; ++tries) {
            i2c = open("/dev/i2c-1"); // the node comes back a moment after the bind
            if (i2c == -ENOENT)
                usleep(10000);
        }
        REQUIRE(i2c == 4);
        REQUIRE(open("/dev/spidev0.0") == 5);
        REQUIRE(open("/sys/bus/platform/drivers/i2c-bcm2835/unbind") == 6);
        REQUIRE(send_request(request(simproto::Op::GpioRequest, 3, [](simproto::Writer& w) {
                    w.str("gpiochip0");
                    w.str("POWER_OFF");
                    w.i32(-1);
                    w.u8(static_cast<uint8_t>(simproto::GpioMode::Input));
                    w.u8(0);
                    w.u8(0);
                })) == 7);
    };
    connect_and_open();

    using simproto::Op;
    corpus.push_back(request(Op::Open, 10, [](simproto::Writer& w) { w.str("/dev/i2c-1"); w.i32(O_RDWR); }));
    corpus.push_back(request(Op::Close, 11, [](simproto::Writer& w) { w.i32(4); }));
    corpus.push_back(request(Op::I2cRdwr, 12, [](simproto::Writer& w) {
            w.i32(4); w.u32(1);
        w.u16(0x29); w.u16(0); w.u16(3); w.bytes(kOrder, sizeof kOrder);
    }));
    corpus.push_back(request(Op::I2cRdwr, 13, [](simproto::Writer& w) {
        w.i32(4); w.u32(2);
        w.u16(0x29); w.u16(0); w.u16(1); w.u8(0x52);
        w.u16(0x29); w.u16(I2C_M_RD); w.u16(7);
    }));
    corpus.push_back(request(Op::SpiMessage, 14, [](simproto::Writer& w) {
        const uint8_t frame[] = {0x08, 0x00, 0, 0, 0, 0};
        w.i32(5); w.u32(1);
        w.u32(sizeof frame); w.u32(500000); w.u16(0); w.u8(8); w.u8(0); w.u8(1); w.u8(1); w.bytes(frame, sizeof frame);
    }));
    corpus.push_back(request(Op::Ioctl, 15, [](simproto::Writer& w) { w.i32(4); w.u64(I2C_FUNCS); w.u64(0); }));
    corpus.push_back(request(Op::Ioctl, 16, [](simproto::Writer& w) { w.i32(5); w.u64(SPI_IOC_WR_MAX_SPEED_HZ); w.u64(500000); }));
    corpus.push_back(request(Op::Write, 17, [](simproto::Writer& w) { w.i32(6); w.u32(12); w.bytes("fe804000.i2c", 12); }));
    corpus.push_back(request(Op::GpioRequest, 18, [](simproto::Writer& w) {
        w.str("gpiochip0"); w.str("KILL_SWITCH"); w.i32(-1); w.u8(1); w.u8(0); w.u8(0);
    }));
    corpus.push_back(request(Op::GpioGet, 19, [](simproto::Writer& w) { w.i32(7); }));
    corpus.push_back(request(Op::GpioSet, 20, [](simproto::Writer& w) { w.i32(7); w.u8(1); }));
    corpus.push_back(request(Op::GpioRelease, 21, [](simproto::Writer& w) { w.i32(7); }));

    int replies = 0;
    std::map<int32_t, int> results; // result (0 for any success) -> count
    const int rounds = 4000;
    for (int i = 0; i < rounds; ++i) {
        if (i % 100 == 99)
            connect_and_open(); // fresh handles: mutations close and release them
        std::vector<uint8_t> m = corpus[pick(corpus.size())];
        switch (pick(5)) {
        case 0: // flip bytes, mostly past the magic so the body parsers see them
            for (size_t k = 1 + pick(4); k > 0; --k)
                m[pick(4) == 0 ? pick(m.size()) : simproto::kHeaderSize + pick(m.size() - simproto::kHeaderSize)] ^=
                    static_cast<uint8_t>(1 + pick(255));
            break;
        case 1: { // a length, count or handle replaced by an edge value
            const size_t at = simproto::kHeaderSize + pick(m.size() - simproto::kHeaderSize);
            const uint32_t v = edges[pick(std::size(edges))];
            for (size_t b = 0; b < 4 && at + b < m.size(); ++b)
                m[at + b] = static_cast<uint8_t>(v >> (8 * b));
            break;
        }
        case 2: // cut short
            m.resize(pick(m.size()));
            break;
        case 3: // extended with junk
            for (size_t k = 1 + pick(64); k > 0; --k)
                m.push_back(static_cast<uint8_t>(pick(256)));
            break;
        default: { // the body of one request under the op of another (GpioWatch would turn the
                   // connection into an event stream, so it is left out)
            uint16_t op = static_cast<uint16_t>(1 + pick(14));
            if (op == static_cast<uint16_t>(Op::GpioWatch))
                op = static_cast<uint16_t>(Op::GpioEvent);
            m[4] = static_cast<uint8_t>(op);
            m[5] = static_cast<uint8_t>(op >> 8);
            break;
        }
        }
        if (m.empty())
            m.push_back(0); // a zero-length datagram is end of file on SOCK_SEQPACKET
        REQUIRE(send(s, m.data(), m.size(), 0) == static_cast<ssize_t>(m.size()));
        INFO("request " << i);
        auto result = got_reply(s);
        REQUIRE(result);
        ++results[*result < 0 ? *result : 0];
        ++replies;
    }
    CHECK(replies == rounds);
    // The mutations got past the header into the handlers: some still succeed, and the
    // handlers' own errors come back, not only "bad message".
    for (auto [result, count] : results)
        UNSCOPED_INFO("result " << result << ": " << count);
    CHECK(results[0] > 0);
    for (int err : {EBADMSG, EBADF, ENOENT, ENOTTY})
        CHECK(results[-err] > 0);
    // Still alive and serving a proper driver (the I2C driver bound again, as a mutated unbind
    // may have left it).
    REQUIRE(f.sim.running());
    connect_and_open();
    close(s);
    SimDeviceIo io;
    REQUIRE(io.connect(f.socket()) == 0);
    I2cDev bus(io, "/dev/i2c-1");
    REQUIRE(bus.open() == 0);
    CHECK(bus.write(0x29, kOrder) == IoError::None);
    CHECK(f.wire_log().back().data == std::vector<uint8_t>(std::begin(kOrder), std::end(kOrder)));
    CHECK(f.sim.running());
}
