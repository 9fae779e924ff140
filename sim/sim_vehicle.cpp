#include "sim/sim_vehicle.hpp"

#include <cerrno>
#include <linux/spi/spidev.h>

namespace caracara::sim {

namespace {
VehicleBodyConfig body_config(const SimConfig& cfg) {
    VehicleBodyConfig b;
    b.vehicle = cfg.vehicle;
    return b;
}
} // namespace

SimVehicle::SimVehicle(const SimConfig& cfg)
    : cfg_(cfg), i2c_(log_, cfg.i2c_clock_hz), gpio_(i2c_, log_, cfg.kill_switch_active_low),
      realistic_(cfg.realistic_timing) {
    for (const auto& spec : cfg_.thrusters) {
        thrusters_.push_back(std::make_unique<ThrusterModel>(spec));
        auto* t = thrusters_.back().get();
        i2c_.attach(t, t->addr7(), spec.mux_addr, spec.mux_channel);
        stepped_.push_back(t);
    }
    // The body is pushed by what the thrusters actually do (after ramp and faults), in the
    // packet's motor numbering; missing and disconnected thrusters push nothing, one mounted
    // reversed pushes the other way.
    body_ = std::make_unique<VehicleBody>([this] {
        std::array<double, 8> f{};
        for (size_t i = 0; i < f.size() && i < thrusters_.size(); ++i)
            if (!cfg_.disconnected[i])
                f[i] = (cfg_.mounted_reversed[i] ? -1.0 : 1.0) * thrusters_[i]->actual_fraction();
        return f;
    }, body_config(cfg_));
    teensy_ = std::make_unique<TeensyModel>(cfg_.teensy, *body_);
    attach_spi(cfg_.spi_device, teensy_.get());
    stepped_.push_back(body_.get());
    stepped_.push_back(teensy_.get());
}

SimVehicle::NodeKind SimVehicle::node_kind(const std::string& path, uint64_t now_ns) const {
    if (path == cfg_.i2c_device)
        return i2c_present(now_ns) ? NodeKind::I2c : NodeKind::None;
    if (path == cfg_.unbind_path)
        return NodeKind::Unbind;
    if (path == cfg_.bind_path)
        return NodeKind::Bind;
    if (spi_.count(path))
        return vanished(NodeKind::Spi, now_ns) ? NodeKind::None : NodeKind::Spi;
    return NodeKind::None;
}

void SimVehicle::vanish(NodeKind kind, uint32_t ms, uint64_t now_ns) {
    const uint64_t until = now_ns + 1'000'000ull * ms;
    if (kind == NodeKind::Spi) {
        spi_gone_until_ = until;
        ++spi_epoch_;
    } else {
        i2c_gone_until_ = until;
        ++i2c_epoch_;
    }
}

bool SimVehicle::vanished(NodeKind kind, uint64_t now_ns) const {
    return now_ns < (kind == NodeKind::Spi ? spi_gone_until_ : i2c_gone_until_);
}

SpiPort* SimVehicle::spi_port(const std::string& path) {
    auto it = spi_.find(path);
    return it == spi_.end() ? nullptr : &it->second;
}

int SimVehicle::sysfs_write(NodeKind which, std::string_view data, uint64_t now_ns) {
    std::string_view id = data;
    while (!id.empty() && (id.back() == '\n' || id.back() == ' '))
        id.remove_suffix(1);
    // The kernel answers ENODEV for a device it does not know or that is not in that state.
    if (id != cfg_.driver_id)
        return -ENODEV;
    if (which == NodeKind::Unbind) {
        if (!bound_)
            return -ENODEV;
        bound_ = false;
        ++unbinds_;
    } else {
        if (bound_)
            return -EBUSY;
        bound_ = true;
        ++binds_;
        // Probing the controller puts the pins back to their I2C function; the node follows
        // once udev has recreated it.
        i2c_.restore_i2c_function();
        node_back_at_ = now_ns + 1'000'000ull * cfg_.rebind_delay_ms;
    }
    return static_cast<int>(data.size());
}

void SimVehicle::attach_spi(const std::string& path, SpiSlave* slave) { spi_[path].slave = slave; }

int SimVehicle::spi_message(SpiPort& port, std::vector<SpiMessageXfer>& xfers, uint64_t start_ns, uint64_t& wire_ns) {
    ++port.messages;
    port.last_transfers = static_cast<uint32_t>(xfers.size());
    port.last_speed_hz = xfers.empty() ? 0 : xfers.front().params.speed_hz;
    port.last_delay_usecs = xfers.empty() ? 0 : xfers.front().params.delay_usecs;
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
