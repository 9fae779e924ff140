// The device seam's GPIO side in process: output lines whose writes land on a FakeWire (the
// kill output and the power-off output, told apart by line name), a kill switch whose edges a
// test makes (set_kill_switch) through an eventfd, as a chip's line would, and the I2C bus's
// SCL and SDA as open-drain lines for a bus clear: they read low while the wire's slave holds
// them (FakeWire::hold_sda, hold_scl), and each clock pulse and STOP lands on the wire.
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
    static constexpr const char* kScl = "I2C_SCL";
    static constexpr const char* kSda = "I2C_SDA";
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
    int scl_driven_ = 1; // what the master drives SCL to (1: let go)
};

} // namespace caracara::test
