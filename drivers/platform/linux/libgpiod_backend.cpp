// GpioBackend on libgpiod's v1 C++ binding (gpiod.hpp 1.6: Debian 12, Raspberry Pi OS bookworm).
// Only this file knows it; libgpiod2_backend.cpp does the same on libgpiod 2 (CMake builds one).
#include "drivers/platform/linux/libgpiod_backend.hpp"

#include "drivers/platform/linux/libgpiod_output_line.hpp"

#include <cerrno>
#include <gpiod.hpp>
#include <system_error>

namespace caracara {

namespace {

int errno_of(const std::exception& e) {
    if (auto* se = dynamic_cast<const std::system_error*>(&e))
        return se->code().value();
    return EIO;
}

class LibgpiodLine final : public GpioLine {
public:
    LibgpiodLine(gpiod::chip chip, gpiod::line line, bool edges) : chip_(std::move(chip)), line_(std::move(line)), edges_(edges) {}
    ~LibgpiodLine() override {
        try {
            line_.release();
        } catch (const std::exception&) {
            // released with the chip anyway
        }
    }
    int get() override {
        try {
            return line_.get_value();
        } catch (const std::exception& e) {
            return -errno_of(e);
        }
    }
    // An input: the kernel refuses a value for it with EPERM; nothing in the daemon asks.
    int set(int) override { return -EPERM; }
    int event_fd() const override {
        if (!edges_)
            return -1;
        try {
            return line_.event_get_fd();
        } catch (const std::exception&) {
            return -1;
        }
    }
    int drain_events() override {
        try {
            int n = 0;
            while (line_.event_wait(std::chrono::nanoseconds(0))) {
                line_.event_read();
                ++n;
            }
            return n;
        } catch (const std::exception& e) {
            return -errno_of(e);
        }
    }

private:
    gpiod::chip chip_;
    gpiod::line line_;
    bool edges_;
};

class LibgpiodBackend final : public GpioBackend {
public:
    explicit LibgpiodBackend(std::string consumer) : consumer_(std::move(consumer)) {}
    std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial, std::string& error) override {
        if (mode == GpioMode::Output || mode == GpioMode::OpenDrain)
            return LibgpiodOutputLine::request(spec, mode, initial, consumer_, error);
        try {
            gpiod::chip chip(spec.chip, gpiod::chip::OPEN_LOOKUP);
            gpiod::line line = spec.offset ? chip.get_line(*spec.offset) : chip.find_line(spec.name);
            if (!line) {
                error = spec.describe() + ": no such line";
                return nullptr;
            }
            // Inputs only: outputs are LibgpiodOutputLine's (returned above).
            gpiod::line_request req;
            req.consumer = consumer_;
            req.request_type = mode == GpioMode::InputEdges ? gpiod::line_request::EVENT_BOTH_EDGES
                                                            : gpiod::line_request::DIRECTION_INPUT;
            if (spec.active_low)
                req.flags |= gpiod::line_request::FLAG_ACTIVE_LOW;
            line.request(req, initial);
            return std::make_unique<LibgpiodLine>(std::move(chip), std::move(line), mode == GpioMode::InputEdges);
        } catch (const std::exception& e) {
            error = spec.describe() + ": " + e.what();
            return nullptr;
        }
    }

private:
    std::string consumer_;
};

} // namespace

std::unique_ptr<GpioBackend> make_libgpiod_backend(const std::string& consumer) {
    return std::make_unique<LibgpiodBackend>(consumer);
}

} // namespace caracara
