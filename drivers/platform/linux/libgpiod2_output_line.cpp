#include "drivers/platform/linux/libgpiod2_output_line.hpp"

#include "drivers/platform/linux/libgpiod2_chip_path.hpp"

#include <cerrno>
#include <cstring>
#include <gpiod.h>

namespace caracara {

namespace {

// The C API's objects, freed on every path out of request().
struct ChipCloser {
    void operator()(gpiod_chip* c) const { gpiod_chip_close(c); }
};
struct SettingsFree {
    void operator()(gpiod_line_settings* s) const { gpiod_line_settings_free(s); }
};
struct LineConfigFree {
    void operator()(gpiod_line_config* c) const { gpiod_line_config_free(c); }
};
struct RequestConfigFree {
    void operator()(gpiod_request_config* c) const { gpiod_request_config_free(c); }
};

gpiod_line_value value_of(int v) { return v ? GPIOD_LINE_VALUE_ACTIVE : GPIOD_LINE_VALUE_INACTIVE; }

} // namespace

std::unique_ptr<GpioLine> Libgpiod2OutputLine::request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                                       const std::string& consumer, std::string& error) {
    const auto fail = [&](const char* what) {
        error = spec.describe() + ": " + (what ? what : std::strerror(errno));
        return nullptr;
    };
    std::unique_ptr<gpiod_chip, ChipCloser> chip(gpiod_chip_open(libgpiod2_chip_path(spec.chip).c_str()));
    if (!chip)
        return fail(nullptr);
    unsigned int offset = 0;
    if (spec.offset) {
        offset = *spec.offset;
    } else {
        const int found = gpiod_chip_get_line_offset_from_name(chip.get(), spec.name.c_str());
        if (found < 0)
            return fail(errno == ENOENT ? "no such line" : nullptr);
        offset = static_cast<unsigned int>(found);
    }
    std::unique_ptr<gpiod_line_settings, SettingsFree> settings(gpiod_line_settings_new());
    std::unique_ptr<gpiod_line_config, LineConfigFree> line_cfg(gpiod_line_config_new());
    std::unique_ptr<gpiod_request_config, RequestConfigFree> req_cfg(gpiod_request_config_new());
    if (!settings || !line_cfg || !req_cfg)
        return fail(nullptr);
    if (gpiod_line_settings_set_direction(settings.get(), GPIOD_LINE_DIRECTION_OUTPUT) < 0 ||
        gpiod_line_settings_set_drive(settings.get(), mode == GpioMode::OpenDrain ? GPIOD_LINE_DRIVE_OPEN_DRAIN
                                                                                  : GPIOD_LINE_DRIVE_PUSH_PULL) < 0 ||
        gpiod_line_settings_set_output_value(settings.get(), value_of(initial)) < 0)
        return fail(nullptr);
    gpiod_line_settings_set_active_low(settings.get(), spec.active_low);
    if (gpiod_line_config_add_line_settings(line_cfg.get(), &offset, 1, settings.get()) < 0)
        return fail(nullptr);
    gpiod_request_config_set_consumer(req_cfg.get(), consumer.c_str());
    // The request outlives the chip handle: it has a file descriptor of its own.
    gpiod_line_request* request = gpiod_chip_request_lines(chip.get(), req_cfg.get(), line_cfg.get());
    if (!request)
        return fail(nullptr);
    return std::unique_ptr<GpioLine>(new Libgpiod2OutputLine(request, offset));
}

Libgpiod2OutputLine::~Libgpiod2OutputLine() { gpiod_line_request_release(request_); }

int Libgpiod2OutputLine::get() {
    const gpiod_line_value v = gpiod_line_request_get_value(request_, offset_);
    if (v == GPIOD_LINE_VALUE_ERROR)
        return -errno;
    return v == GPIOD_LINE_VALUE_ACTIVE ? 1 : 0;
}

int Libgpiod2OutputLine::set(int value) {
    return gpiod_line_request_set_value(request_, offset_, value_of(value)) < 0 ? -errno : 0;
}

bool Libgpiod2OutputLine::set_in_signal_handler(int value) noexcept {
    const int saved = errno;
    const bool ok = gpiod_line_request_set_value(request_, offset_, value_of(value)) == 0;
    errno = saved;
    return ok;
}

} // namespace caracara
