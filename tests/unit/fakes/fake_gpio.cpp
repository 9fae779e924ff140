#include "tests/unit/fakes/fake_gpio.hpp"

#include <cerrno>
#include <cstdint>
#include <sys/eventfd.h>
#include <unistd.h>

namespace caracara::test {

class FakeGpio::Line final : public GpioLine {
public:
    Line(FakeGpio& gpio, std::string name, int value) : gpio_(gpio), name_(std::move(name)), value_(value) {
        if (name_ == kScl)
            gpio_.scl_driven_ = value;
        record();
    }
    ~Line() override {
        if (name_ == kScl)
            gpio_.scl_driven_ = 1; // let go
    }
    int get() override {
        if (name_ == kKillSwitch)
            return gpio_.switch_set_;
        // Open drain: a line let go reads low while the slave holds it.
        if (name_ == kScl)
            return value_ && !gpio_.wire_.scl_low();
        if (name_ == kSda)
            return value_ && !gpio_.wire_.sda_low();
        return gpio_.outputs_gone_ ? -ENODEV : value_;
    }
    int set(int value) override {
        if (name_ == kScl || name_ == kSda) {
            bus_line(value);
            return 0;
        }
        if (gpio_.outputs_gone_)
            return -ENODEV;
        value_ = value;
        record();
        return 0;
    }
    int event_fd() const override { return name_ == kKillSwitch ? gpio_.switch_fd_ : -1; }
    int drain_events() override {
        uint64_t n = 0;
        return ::read(gpio_.switch_fd_, &n, sizeof n) == sizeof n ? static_cast<int>(n) : 0;
    }

private:
    // SCL let go after being driven low is a clock pulse; SDA let go while SCL is high, a STOP.
    void bus_line(int value) {
        const bool rise = value && !value_;
        value_ = value;
        if (name_ == kScl)
            gpio_.scl_driven_ = value;
        if (rise && name_ == kScl)
            gpio_.wire_.scl_pulse();
        else if (rise && name_ == kSda && gpio_.scl_driven_ && !gpio_.wire_.scl_low())
            gpio_.wire_.add({WireEvent::Kind::Stop, 0, 0, 0});
    }
    void record() {
        if (name_ == kKillOutput)
            gpio_.wire_.add({WireEvent::Kind::KillOutput, 0, value_, 0});
        else if (name_ == kPowerOff)
            gpio_.wire_.add({WireEvent::Kind::PowerOff, 0, value_, 0});
    }
    FakeGpio& gpio_;
    std::string name_;
    int value_;
};

std::string FakeGpio::config_section() {
    return std::string("[gpio]\n") + "kill_switch = { chip = \"gpiochip0\", line = \"" + kKillSwitch + "\" }\n" +
           "kill_output = { chip = \"gpiochip0\", line = \"" + kKillOutput + "\" }\n" +
           "power_off_output = { chip = \"gpiochip0\", line = \"" + kPowerOff + "\" }\n" +
           "scl = { chip = \"gpiochip0\", line = \"" + kScl + "\" }\n" +
           "sda = { chip = \"gpiochip0\", line = \"" + kSda + "\" }\n";
}

FakeGpio::FakeGpio(FakeWire& wire) : wire_(wire), switch_fd_(eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}

FakeGpio::~FakeGpio() {
    if (switch_fd_ >= 0)
        ::close(switch_fd_);
}

std::unique_ptr<GpioLine> FakeGpio::request(const GpioLineSpec& spec, GpioMode, int initial, std::string& error) {
    if (spec.name != kKillSwitch && spec.name != kKillOutput && spec.name != kPowerOff && spec.name != kScl &&
        spec.name != kSda) {
        error = "no line " + spec.describe();
        return nullptr;
    }
    if ((spec.name == kKillOutput || spec.name == kPowerOff) && outputs_gone_) {
        error = "gpiochip0 is gone";
        return nullptr;
    }
    return std::make_unique<Line>(*this, spec.name, initial);
}

void FakeGpio::set_kill_switch(bool set) {
    switch_set_ = set;
    const uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(switch_fd_, &one, sizeof one);
}

} // namespace caracara::test
