// The SPI link under fuzz_teensy: a DeviceIo playing the Teensy from the fuzz input. Each
// SPI_IOC_MESSAGE is answered as an ack with answer bytes, a busy, raw bytes, or a failed or
// short transfer. It checks the spidev marshalling (one transfer per frame, or one per byte
// with the configured delay) and records every frame clocked out, for the harness's checks.
#pragma once

#include "core/link_config.hpp"
#include "fuzz/byte_source.hpp"
#include "fuzz/check.hpp"
#include "drivers/platform/device_io.hpp"

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <linux/spi/spidev.h>
#include <vector>

namespace caracara::fuzz {

class ShadowSpiBus final : public DeviceIo {
public:
    ShadowSpiBus(ByteSource& in, SpiConfig config) : in_(in), config_(config) {}

    // What the Teensy did with the last frame (kinds of reply).
    enum class Answer : uint8_t { Ack, Busy, Raw, Failed, Short };
    struct Sent {
        std::vector<uint8_t> tx;
        std::vector<uint8_t> rx;
        Answer answer;
    };
    std::vector<Sent> sent;  // every message clocked out, in order

    int open(const char*, int) override { return 4; }
    int close(int) override { return 0; }
    int write(int, const void*, size_t) override { return -EBADF; }
    int ioctl(int fd, unsigned long request, void* arg) override {
        FUZZ_CHECK(fd == 4, "ioctl on fd %d", fd);
        if (request == SPI_IOC_WR_MODE) {
            FUZZ_CHECK(*static_cast<uint8_t*>(arg) == SPI_MODE_0, "SPI mode not 0");
            return 0;
        }
        if (request == SPI_IOC_WR_BITS_PER_WORD) {
            FUZZ_CHECK(*static_cast<uint8_t*>(arg) == 8, "not 8 bits per word");
            return 0;
        }
        if (request == SPI_IOC_WR_MAX_SPEED_HZ) {
            FUZZ_CHECK(*static_cast<uint32_t*>(arg) == config_.speed_hz, "speed not the configured one");
            return 0;
        }
        FUZZ_CHECK(_IOC_TYPE(request) == SPI_IOC_MAGIC && _IOC_NR(request) == 0 && _IOC_DIR(request) == _IOC_WRITE,
                   "unexpected ioctl %#lx", request);
        const std::size_t n = _IOC_SIZE(request) / sizeof(spi_ioc_transfer);
        FUZZ_CHECK(n * sizeof(spi_ioc_transfer) == _IOC_SIZE(request) && n > 0, "SPI_IOC_MESSAGE size");
        return message(static_cast<spi_ioc_transfer*>(arg), n);
    }

private:
    int message(spi_ioc_transfer* t, std::size_t n) {
        Sent s;
        if (config_.byte_delay_us == 0) {
            FUZZ_CHECK(n == 1, "%zu transfers without a per-byte delay", n);
        } else {
            for (std::size_t i = 0; i < n; ++i)
                FUZZ_CHECK(t[i].len == 1 && t[i].delay_usecs == config_.byte_delay_us && !t[i].cs_change,
                           "per-byte transfer %zu: len %u delay %u cs_change %u", i, t[i].len, t[i].delay_usecs,
                           t[i].cs_change);
        }
        for (std::size_t i = 0; i < n; ++i) {
            FUZZ_CHECK(t[i].speed_hz == config_.speed_hz && t[i].bits_per_word == 8 && t[i].tx_buf && t[i].rx_buf,
                       "transfer %zu badly set up", i);
            const auto* tx = reinterpret_cast<const uint8_t*>(static_cast<uintptr_t>(t[i].tx_buf));
            s.tx.insert(s.tx.end(), tx, tx + t[i].len);
        }
        s.rx.assign(s.tx.size(), 0);
        const uint8_t how = in_.u8();
        s.answer = static_cast<Answer>(how % 5);
        int ret = static_cast<int>(s.tx.size());
        switch (s.answer) {
        case Answer::Ack:
        case Answer::Busy: {
            // The Teensy clocks its answer bytes just before the ack slot; which bytes those
            // are is the frame's business, so everything before the ack comes from the input.
            const auto b = in_.bytes(s.rx.size() - 1);
            std::copy(b.begin(), b.end(), s.rx.begin());
            s.rx.back() = s.answer == Answer::Ack ? s.tx.front() : 0xFF;
            break;
        }
        case Answer::Raw: {
            const auto b = in_.bytes(s.rx.size());
            std::copy(b.begin(), b.end(), s.rx.begin());
            break;
        }
        case Answer::Failed: ret = -(how >> 3 ? EIO : ETIMEDOUT); break;
        case Answer::Short: ret = static_cast<int>(s.tx.size()) - 1 - (how >> 3) % static_cast<int>(s.tx.size()); break;
        }
        if (ret >= 0) {
            // Per-byte mode scatters the reply over the transfers' rx buffers.
            std::size_t off = 0;
            for (std::size_t i = 0; i < n; ++i) {
                auto* rx = reinterpret_cast<uint8_t*>(static_cast<uintptr_t>(t[i].rx_buf));
                std::memcpy(rx, s.rx.data() + off, t[i].len);
                off += t[i].len;
            }
        }
        sent.push_back(std::move(s));
        return ret;
    }

    ByteSource& in_;
    SpiConfig config_;
};

} // namespace caracara::fuzz
