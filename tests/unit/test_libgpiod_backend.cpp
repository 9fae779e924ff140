// The libgpiod backend this build has (v1 on libgpiod 1.6, v2 on libgpiod 2.x: the same test
// for both). Without a GPIO chip (none on CI) only the paths that need no chip run: a chip that
// cannot be found or opened fails the request with the line's description in the error.
// Requests on a real chip (modes, active-low, edges, lookups, consumer) are covered by the QEMU
// kernel test: CTest `kernel` for this build, `system_debian13` for the libgpiod 2 build.
#include "drivers/platform/gpio_line.hpp"
#include "drivers/platform/linux/libgpiod_backend.hpp"
#include "tests/catch.hpp"

#include <string>

using namespace caracara;

namespace {

GpioLineSpec spec_of(std::string chip, std::string name, std::optional<uint32_t> offset = {}) {
    GpioLineSpec s;
    s.chip = std::move(chip);
    s.name = std::move(name);
    s.offset = offset;
    return s;
}

} // namespace

TEST_CASE("GpioLineSpec::describe names the chip and the line") {
    CHECK(spec_of("gpiochip0", "GPIO17").describe() == "gpiochip0:GPIO17");
    CHECK(spec_of("gpiochip0", "", 17).describe() == "gpiochip0 line 17");
}

TEST_CASE("a chip that does not exist fails the request with the line in the error") {
    auto backend = make_libgpiod_backend("caracara-test");
    REQUIRE(backend);
    const GpioMode modes[] = {GpioMode::Input, GpioMode::InputEdges, GpioMode::Output, GpioMode::OpenDrain};
    for (GpioMode mode : modes) {
        for (const auto& spec : {spec_of("caracara-no-such-chip", "KILL"), spec_of("987", "", 3),
                                 spec_of("/dev/caracara-no-such-gpiochip", "", 0)}) {
            std::string error;
            CAPTURE(spec.describe(), static_cast<int>(mode));
            auto line = backend->request(spec, mode, 0, error);
            CHECK_FALSE(line);
            CHECK_THAT(error, Catch::StartsWith(spec.describe() + ": "));
            CHECK(error.size() > spec.describe().size() + 2);
        }
    }
}

TEST_CASE("a device that is not a GPIO chip is refused") {
    auto backend = make_libgpiod_backend("caracara-test");
    std::string error;
    auto line = backend->request(spec_of("/dev/null", "", 0), GpioMode::Input, 0, error);
    CHECK_FALSE(line);
    CHECK_THAT(error, Catch::StartsWith("/dev/null line 0: "));
}
