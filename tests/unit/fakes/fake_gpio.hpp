// The device seam's GPIO side in process: output lines whose writes land on a FakeWire (the
// kill output and the power-off output, told apart by line name), and a kill switch whose
// edges a test makes (set_kill_switch) through an eventfd, as a chip's line would.
#pragma once

#include "drivers/platform/gpio_backend.hpp"
#include "tests/unit/fakes/fake_wire.hpp"

#include <memory>
#include <string>

namespace caracara::test {

class FakeGpio final : public GpioBackend {
public:
    // The line names the test configuration gives them.
    static constexpr const char* kKillSwitch = "KILL_SWITCH";
    static constexpr const char* kKillOutput = "KILL_OUT";
    static constexpr const char* kPowerOff = "POWER_OFF";
    // The [gpio] section that names them.
    static std::string config_section();

    explicit FakeGpio(FakeWire& wire);
    ~FakeGpio() override;

    std::unique_ptr<GpioLine> request(const GpioLineSpec& spec, GpioMode mode, int initial,
                                      std::string& error) override;
    // Moves the kill switch (set = kill) and makes an edge.
    void set_kill_switch(bool set);
    // The output lines' chip goes away (their reads and writes fail ENODEV, a request is
    // refused) or comes back.
    void set_outputs_gone(bool gone) { outputs_gone_ = gone; }

private:
    class Line;
    FakeWire& wire_;
    int switch_fd_ = -1;
    bool switch_set_ = false;
    bool outputs_gone_ = false;
};

} // namespace caracara::test
