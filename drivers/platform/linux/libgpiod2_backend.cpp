#include "drivers/platform/linux/libgpiod2_backend.hpp"

#include "drivers/platform/linux/libgpiod2_chip_path.hpp"
#include "drivers/platform/linux/libgpiod2_line.hpp"
#include "drivers/platform/linux/libgpiod2_output_line.hpp"
#include "drivers/platform/linux/libgpiod_backend.hpp"

#include <cerrno>
#include <cstring>
#include <gpiod.hpp>
#include <system_error>

namespace caracara {

namespace {

// Inputs only: outputs are Libgpiod2OutputLine's.
gpiod::line_settings input_settings(GpioMode mode, bool active_low) {
    gpiod::line_settings s;
    s.set_direction(gpiod::line::direction::INPUT);
    if (mode == GpioMode::InputEdges)
        s.set_edge_detection(gpiod::line::edge::BOTH);
    s.set_active_low(active_low);
    return s;
}

} // namespace

std::unique_ptr<GpioLine> Libgpiod2Backend::request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                                    std::string& error) {
    if (mode == GpioMode::Output || mode == GpioMode::OpenDrain)
        return Libgpiod2OutputLine::request(spec, mode, initial, consumer_, error);
    try {
        gpiod::chip chip(libgpiod2_chip_path(spec.chip));
        gpiod::line::offset offset = 0;
        if (spec.offset) {
            offset = *spec.offset;
        } else {
            const int found = chip.get_line_offset_from_name(spec.name);
            if (found < 0) {
                error = spec.describe() + ": no such line";
                return nullptr;
            }
            offset = static_cast<unsigned int>(found);
        }
        gpiod::line_request request = chip.prepare_request()
                                          .set_consumer(consumer_)
                                          .add_line_settings(offset, input_settings(mode, spec.active_low))
                                          .do_request();
        return std::make_unique<Libgpiod2Line>(std::move(request), offset, mode == GpioMode::InputEdges);
    } catch (const std::system_error& e) {
        error = spec.describe() + ": " + e.what();
        return nullptr;
    } catch (const std::exception& e) {
        // EINVAL and the like come as exceptions whose text lacks the reason: add it, as v1 has it.
        error = spec.describe() + ": " + e.what() + ": " + std::strerror(Libgpiod2Line::errno_of(e));
        return nullptr;
    }
}

std::unique_ptr<GpioBackend> make_libgpiod_backend(const std::string& consumer) {
    return std::make_unique<Libgpiod2Backend>(consumer);
}

} // namespace caracara
