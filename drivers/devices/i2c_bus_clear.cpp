#include "drivers/devices/i2c_bus_clear.hpp"

#include "drivers/platform/io_error.hpp"

#include <cerrno>
#include <ctime>
#include <fcntl.h>

namespace caracara {

namespace {
void wait_ns(uint32_t ns) {
    timespec ts{0, static_cast<long>(ns)};
    while (nanosleep(&ts, &ts) < 0 && errno == EINTR) {
    }
}

BusClearResult fail(BusClearResult::Outcome o, unsigned pulses, std::string msg) {
    BusClearResult r;
    r.outcome = o;
    r.pulses = pulses;
    r.message = std::move(msg);
    return r;
}
} // namespace

BusClearResult i2c_bus_clear(GpioBackend& gpio, const GpioLineSpec& scl_spec, const GpioLineSpec& sda_spec,
                             uint32_t half_period_ns) {
    if (half_period_ns < 5000)
        half_period_ns = 5000;
    std::string err;
    // Released (high) at request: open drain never drives a line high, it only lets go.
    auto scl = gpio.request(scl_spec, GpioMode::OpenDrain, 1, err);
    if (!scl)
        return fail(BusClearResult::Outcome::GpioError, 0, "SCL: " + err);
    auto sda = gpio.request(sda_spec, GpioMode::OpenDrain, 1, err);
    if (!sda)
        return fail(BusClearResult::Outcome::GpioError, 0, "SDA: " + err);
    wait_ns(half_period_ns);
    int v = scl->get();
    if (v < 0)
        return fail(BusClearResult::Outcome::GpioError, 0, "reading SCL: " + errno_name(-v));
    if (v == 0)
        return fail(BusClearResult::Outcome::SclHeldLow, 0, "SCL is held low: clocking cannot clear the bus");

    unsigned pulses = 0;
    while (pulses < 9) {
        int s = sda->get();
        if (s < 0)
            return fail(BusClearResult::Outcome::GpioError, pulses, "reading SDA: " + errno_name(-s));
        if (s == 1)
            break;
        scl->set(0);
        wait_ns(half_period_ns);
        scl->set(1);
        wait_ns(half_period_ns);
        ++pulses;
        if (scl->get() == 0)
            return fail(BusClearResult::Outcome::SclHeldLow, pulses, "SCL stayed low after a clock pulse");
    }
    if (sda->get() != 1)
        return fail(BusClearResult::Outcome::SdaStillLow, pulses, "SDA still low after 9 clock pulses");

    // STOP: SDA goes low to high while SCL is high.
    scl->set(0);
    wait_ns(half_period_ns);
    sda->set(0);
    wait_ns(half_period_ns);
    scl->set(1);
    wait_ns(half_period_ns);
    sda->set(1);
    wait_ns(half_period_ns);
    BusClearResult r;
    r.outcome = BusClearResult::Outcome::Cleared;
    r.pulses = pulses;
    return r; // the lines are released as the GpioLine objects go
}

int sysfs_write(DeviceIo& io, const std::string& path, const std::string& text) {
    int fd = io.open(path.c_str(), O_WRONLY);
    if (fd < 0)
        return fd;
    int r = io.write(fd, text.data(), text.size());
    io.close(fd);
    return r < 0 ? r : 0;
}

} // namespace caracara
