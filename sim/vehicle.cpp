#include "vehicle.hpp"

#include <cerrno>
#include <linux/spi/spidev.h>

namespace caracara::sim {

SimVehicle::SimVehicle(const SimConfig& cfg)
    : cfg_(cfg), i2c_(log_, cfg.i2c_clock_hz), realistic_(cfg.realistic_timing) {
    for (const auto& spec : cfg_.thrusters) {
        thrusters_.push_back(std::make_unique<ThrusterModel>(spec));
        auto* t = thrusters_.back().get();
        i2c_.attach(t, t->addr7(), spec.mux_addr, spec.mux_channel);
        stepped_.push_back(t);
    }
    // The body is pushed by what the thrusters actually do (after ramp and faults), in the
    // packet's motor numbering; missing thrusters push nothing.
    body_ = std::make_unique<VehicleBody>([this] {
        std::array<double, 8> f{};
        for (size_t i = 0; i < f.size() && i < thrusters_.size(); ++i)
            f[i] = thrusters_[i]->actual_fraction();
        return f;
    });
    teensy_ = std::make_unique<TeensyModel>(TeensyConfig{}, *body_);
    attach_spi(cfg_.spi_device, teensy_.get());
    stepped_.push_back(body_.get());
    stepped_.push_back(teensy_.get());
}

SimVehicle::NodeKind SimVehicle::node_kind(const std::string& path) const {
    if (path == cfg_.i2c_device)
        return NodeKind::I2c;
    if (spi_.count(path))
        return NodeKind::Spi;
    return NodeKind::None;
}

SpiPort* SimVehicle::spi_port(const std::string& path) {
    auto it = spi_.find(path);
    return it == spi_.end() ? nullptr : &it->second;
}

void SimVehicle::attach_spi(const std::string& path, SpiSlave* slave) { spi_[path].slave = slave; }

int SimVehicle::spi_message(SpiPort& port, std::vector<SpiMessageXfer>& xfers, uint64_t start_ns, uint64_t& wire_ns) {
    ++port.messages;
    uint64_t t = start_ns;
    int total = 0;
    WireEntry e;
    e.bus = "spi";
    e.transaction = log_.new_transaction();
    // A slave sampling in mode 0 sees shifted garbage if the master clocks another mode.
    const bool garbled = port.mode != SPI_MODE_0 || port.bits_per_word != 8 || port.lsb_first;
    if (garbled)
        ++port.mode_mismatches;
    for (auto& x : xfers) {
        const uint32_t hz = x.params.speed_hz ? x.params.speed_hz : port.max_speed_hz;
        if (x.tx.empty())
            x.tx.assign(x.len, 0);
        x.rx.assign(x.len, 0);
        if (!garbled && port.slave)
            port.slave->transfer(x.tx, x.rx, x.params, t);
        t += 8ull * x.len * 1000000000ull / (hz ? hz : 1) + 1000ull * x.params.delay_usecs;
        e.data.insert(e.data.end(), x.tx.begin(), x.tx.end());
        e.miso.insert(e.miso.end(), x.rx.begin(), x.rx.end());
        total += static_cast<int>(x.len);
        if (x.params.cs_change && port.slave)
            port.slave->end_message(t);
    }
    if (port.slave)
        port.slave->end_message(t);
    e.result = garbled ? "mode-mismatch" : (port.slave ? "ok" : "no-device");
    e.time_ns = t;
    log_.append(std::move(e));
    wire_ns = t - start_ns;
    return total;
}

void SimVehicle::step(double dt_s, uint64_t now_ns) {
    for (auto* s : stepped_)
        s->step(dt_s, now_ns);
}

} // namespace caracara::sim
