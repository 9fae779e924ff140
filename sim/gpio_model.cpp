#include "sim/gpio_model.hpp"

#include <cerrno>

namespace caracara::sim {

GpioModel::GpioModel(I2cBusModel& bus, WireLog& log, bool kill_switch_active_low)
    : bus_(bus), log_(log), kill_switch_active_low_(kill_switch_active_low) {
    info_ = {{"GPIO2", kSda}, {"GPIO3", kScl}, {"KILL_SWITCH", kKillSwitch}, {"POWER_OFF", kPowerOff}, {"KILL_OUT", kKillOut}};
    lines_.resize(info_.size());
    gone_.resize(info_.size());
    epochs_.resize(info_.size());
}

int GpioModel::find(const std::string& chip, const std::string& name, int offset) const {
    if (chip != kChip && chip != std::string("/dev/") + kChip)
        return -ENOENT;
    for (size_t i = 0; i < info_.size(); ++i)
        if ((offset >= 0 && info_[i].offset == static_cast<uint32_t>(offset)) || (offset < 0 && info_[i].name == name))
            return static_cast<int>(i);
    return -ENOENT;
}

bool GpioModel::physical(size_t i) const {
    const Line& l = lines_[i];
    const bool driven = !l.requested || l.mode == GpioMode::Input || l.mode == GpioMode::InputEdges ? true : l.drive;
    switch (info_[i].offset) {
    case kSda: return driven && bus_.slaves_release_sda(); // wired-AND with every slave
    case kScl: return driven && bus_.slaves_release_scl();
    case kKillSwitch: return kill_switch_engaged_ != kill_switch_active_low_;
    default: return l.requested && (l.mode == GpioMode::Output || l.mode == GpioMode::OpenDrain) ? l.drive : false;
    }
}

bool GpioModel::level(uint32_t offset) const {
    for (size_t i = 0; i < info_.size(); ++i)
        if (info_[i].offset == offset)
            return physical(i);
    return false;
}

std::vector<bool> GpioModel::levels() const {
    std::vector<bool> v(info_.size());
    for (size_t i = 0; i < v.size(); ++i)
        v[i] = physical(i);
    return v;
}

int GpioModel::request(int line, GpioMode mode, bool active_low, int initial, uint64_t now_ns) {
    Line& l = lines_[static_cast<size_t>(line)];
    if (gone_[static_cast<size_t>(line)])
        return -ENODEV;
    if (l.requested)
        return -EBUSY;
    const uint32_t off = info_[static_cast<size_t>(line)].offset;
    const bool is_input_only = off == kKillSwitch;
    if (is_input_only && mode != GpioMode::Input && mode != GpioMode::InputEdges)
        return -EPERM;
    auto before = levels();
    l.requested = true;
    l.mode = mode;
    l.active_low = active_low;
    l.drive = (initial != 0) != active_low;
    if (off == kSda || off == kScl)
        bus_.set_pins_to_gpio();
    update(now_ns, before);
    return 0;
}

int GpioModel::get(int line) const {
    const Line& l = lines_[static_cast<size_t>(line)];
    if (gone_[static_cast<size_t>(line)])
        return -ENODEV;
    return physical(static_cast<size_t>(line)) != l.active_low ? 1 : 0;
}

int GpioModel::set(int line, int logical, uint64_t now_ns) {
    Line& l = lines_[static_cast<size_t>(line)];
    if (gone_[static_cast<size_t>(line)])
        return -ENODEV;
    if (l.mode == GpioMode::Input || l.mode == GpioMode::InputEdges)
        return -EPERM;
    auto before = levels();
    l.drive = (logical != 0) != l.active_low;
    update(now_ns, before);
    return 0;
}

void GpioModel::release(int line, uint64_t now_ns) {
    auto before = levels();
    lines_[static_cast<size_t>(line)] = Line{};
    update(now_ns, before);
}

void GpioModel::set_present(int line, bool present, uint64_t now_ns) {
    const auto i = static_cast<size_t>(line);
    if (gone_[i] == !present)
        return;
    if (!present) {
        release(line, now_ns); // its level changes as an unrequested line's: logged as an edge
        ++epochs_[i];
    }
    gone_[i] = !present;
    WireEntry e;
    e.bus = "gpio";
    e.addr = static_cast<uint16_t>(info_[i].offset);
    e.time_ns = now_ns;
    e.result = present ? "back" : "gone";
    log_.append(std::move(e));
    if (!present && on_gone)
        on_gone(line);
}

void GpioModel::set_kill_switch(bool engaged, uint64_t now_ns) {
    auto before = levels();
    kill_switch_engaged_ = engaged;
    update(now_ns, before);
}

void GpioModel::update(uint64_t now_ns, const std::vector<bool>& before) {
    size_t sda = 0, scl = 0;
    for (size_t i = 0; i < info_.size(); ++i) {
        if (info_[i].offset == kSda) sda = i;
        if (info_[i].offset == kScl) scl = i;
    }
    // Line events in the wire log (the kinds are in wire_log.hpp), stamped now.
    auto line_event = [&](const char* bus, const char* what, uint32_t offset = 0, std::vector<uint8_t> data = {}) {
        WireEntry e;
        e.bus = bus;
        e.addr = static_cast<uint16_t>(offset);
        e.data = std::move(data);
        e.time_ns = now_ns;
        e.result = what;
        log_.append(std::move(e));
    };
    // SCL rising: a clock pulse the stuck slave counts. Order matters: the slave may let SDA go.
    if (!before[scl] && physical(scl)) {
        ++scl_pulses_;
        if (last_scl_rise_ns_) {
            const uint64_t period = now_ns - last_scl_rise_ns_;
            if (min_scl_period_ns_ == 0 || period < min_scl_period_ns_)
                min_scl_period_ns_ = period;
        }
        last_scl_rise_ns_ = now_ns;
        bus_.on_scl_rising(now_ns);
        line_event("i2c-lines", "scl-pulse");
    }
    auto after = levels();
    // START and STOP are SDA edges while SCL is high (UM10204 3.1.4).
    if (after[scl] && before[scl]) {
        if (!before[sda] && after[sda]) {
            ++stops_;
            line_event("i2c-lines", "stop");
        } else if (before[sda] && !after[sda]) {
            line_event("i2c-lines", "start");
        }
    }
    // Every other line's level change goes into the wire log (see the header), then to the
    // edge watchers: the log's stamp is the moment the daemon's edge event can fire.
    for (size_t i = 0; i < info_.size(); ++i) {
        if (before[i] == after[i])
            continue;
        if (i != sda && i != scl)
            line_event("gpio", "edge", info_[i].offset, {static_cast<uint8_t>(after[i])});
        if (on_change)
            on_change(static_cast<int>(i), get(static_cast<int>(i)), now_ns);
    }
}

} // namespace caracara::sim
