#include "drivers/platform/linux/libgpiod_output_line.hpp"

#include <cerrno>
#include <cstring>
#include <gpiod.h>

namespace caracara {

std::unique_ptr<GpioLine> LibgpiodOutputLine::request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                                      const std::string& consumer, std::string& error) {
    gpiod_chip* chip = gpiod_chip_open_lookup(spec.chip.c_str());
    if (!chip) {
        error = spec.describe() + ": " + std::strerror(errno);
        return nullptr;
    }
    gpiod_line* line = spec.offset ? gpiod_chip_get_line(chip, *spec.offset) : gpiod_chip_find_line(chip, spec.name.c_str());
    if (!line) {
        error = spec.describe() + ": no such line";
        gpiod_chip_close(chip);
        return nullptr;
    }
    int flags = 0;
    if (mode == GpioMode::OpenDrain)
        flags |= GPIOD_LINE_REQUEST_FLAG_OPEN_DRAIN;
    if (spec.active_low)
        flags |= GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW;
    if (gpiod_line_request_output_flags(line, consumer.c_str(), flags, initial ? 1 : 0) < 0) {
        error = spec.describe() + ": " + std::strerror(errno);
        gpiod_chip_close(chip);
        return nullptr;
    }
    return std::unique_ptr<GpioLine>(new LibgpiodOutputLine(chip, line));
}

LibgpiodOutputLine::~LibgpiodOutputLine() {
    gpiod_line_release(line_);
    gpiod_chip_close(chip_);
}

int LibgpiodOutputLine::get() {
    const int v = gpiod_line_get_value(line_);
    return v < 0 ? -errno : v;
}

int LibgpiodOutputLine::set(int value) { return gpiod_line_set_value(line_, value ? 1 : 0) < 0 ? -errno : 0; }

bool LibgpiodOutputLine::set_in_signal_handler(int value) noexcept {
    const int saved = errno;
    const bool ok = gpiod_line_set_value(line_, value ? 1 : 0) == 0;
    errno = saved;
    return ok;
}

} // namespace caracara
