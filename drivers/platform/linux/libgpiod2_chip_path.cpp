#include "drivers/platform/linux/libgpiod2_chip_path.hpp"

#include <filesystem>
#include <gpiod.hpp>
#include <system_error>

namespace caracara {

namespace {

bool all_digits(const std::string& s) {
    if (s.empty())
        return false;
    for (char c : s)
        if (c < '0' || c > '9')
            return false;
    return true;
}

} // namespace

std::string libgpiod2_chip_path(const std::string& descr) {
    namespace fs = std::filesystem;
    if (all_digits(descr))
        return "/dev/gpiochip" + descr;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator("/dev", ec)) {
        if (!gpiod::is_gpiochip_device(entry.path()))
            continue;
        try {
            if (gpiod::chip(entry.path()).get_info().label() == descr)
                return entry.path().string();
        } catch (const std::exception&) {
            // a chip that cannot be opened or read is not the one asked for
        }
    }
    return descr.rfind("/dev/", 0) == 0 ? descr : "/dev/" + descr;
}

} // namespace caracara
