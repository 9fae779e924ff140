#include "sim/sim_config.hpp"

#include "core/toml_checker.hpp"
#include "core/toml_text.hpp"
#include "core/vehicle_config.hpp"

#include <fstream>
#include <sstream>
#include <toml++/toml.h>

namespace caracara::sim {

SimConfig default_sim_config() {
    SimConfig c;
    // Same default vehicle as caracarad: eight SeaBotix controllers at distinct even addresses.
    for (int mt : {0x52, 0x56, 0x58, 0x5A, 0x5C, 0x5E, 0x60, 0x62}) {
        ThrusterSpec s;
        s.mt = static_cast<uint8_t>(mt);
        c.thrusters.push_back(s);
    }
    return c;
}

namespace {
template <typename T>
bool get_int(const toml::table& t, const char* key, const std::string& where, T lo, T hi, T& out, std::string& err) {
    auto node = t.get(key);
    if (!node)
        return true;
    // Integers only, as caracarad's checker takes them: node::value<int64_t>() would also take a
    // float, truncating 1.5 to 1, and toml++ 3.3 casts one beyond int64 before checking its
    // range (undefined behaviour; found by fuzz_config).
    const auto* v = node->as_integer();
    if (!v || v->get() < lo || v->get() > hi) {
        err = where + key + ": must be an integer between " + std::to_string(lo) + " and " + std::to_string(hi);
        return false;
    }
    out = static_cast<T>(v->get());
    return true;
}

bool get_double(const toml::table& t, const char* key, const std::string& where, double lo, double hi, double& out,
                std::string& err) {
    auto node = t.get(key);
    if (!node)
        return true;
    const auto v = node->value<double>();
    if (!v || !(*v >= lo && *v <= hi)) {
        err = where + key + ": must be a number between " + std::to_string(lo) + " and " + std::to_string(hi);
        return false;
    }
    out = *v;
    return true;
}

// A list of motor numbers 0..7, each marking its flag.
bool get_motor_set(const toml::table& t, const char* key, std::array<bool, 8>& out, std::string& err) {
    auto node = t.get(key);
    if (!node)
        return true;
    const auto* arr = node->as_array();
    if (!arr) {
        err = std::string("sim.") + key + ": must be an array of motor numbers 0..7";
        return false;
    }
    for (const auto& e : *arr) {
        const auto* i = e.as_integer();
        if (!i || i->get() < 0 || i->get() > 7) {
            err = std::string("sim.") + key + ": must be an array of motor numbers 0..7";
            return false;
        }
        out[static_cast<size_t>(i->get())] = true;
    }
    return true;
}
} // namespace

bool parse_sim_config(const std::string& text, SimConfig& out, std::string& error) {
    // The same guard as caracarad's reader of this file (core/toml_text.hpp says why).
    if (std::string e = non_ascii_outside_comments(text); !e.empty()) {
        error = e;
        return false;
    }
    toml::table root;
    try {
        root = toml::parse(text);
    } catch (const toml::parse_error& e) {
        std::ostringstream os;
        os << "line " << e.source().begin.line << ": " << e.description();
        error = os.str();
        return false;
    }
    SimConfig c = default_sim_config();
    if (auto i2c = root["i2c"].as_table()) {
        if (auto d = (*i2c)["device"].value<std::string>())
            c.i2c_device = *d;
        if (!get_int<uint32_t>(*i2c, "clock_hz", "i2c.", 1000, 3400000, c.i2c_clock_hz, error))
            return false;
    }
    if (auto sim = root["sim"].as_table()) {
        if (auto rt = (*sim)["realistic_timing"].value<bool>())
            c.realistic_timing = *rt;
        if (auto v = (*sim)["driver_id"].value<std::string>())
            c.driver_id = *v;
        if (!get_int<uint32_t>(*sim, "rebind_delay_ms", "sim.", 0, 60000, c.rebind_delay_ms, error))
            return false;
        if (!get_int<uint32_t>(*sim, "wire_log_entries", "sim.", 1, 10000000, c.wire_log_entries, error))
            return false;
        if (auto v = (*sim)["kill_switch_active_low"].value<bool>())
            c.kill_switch_active_low = *v;
        if (!get_motor_set(*sim, "reversed_thrusters", c.mounted_reversed, error) ||
            !get_motor_set(*sim, "disconnected_thrusters", c.disconnected, error))
            return false;
        if (!get_double(*sim, "orientation_noise_rad", "sim.", 0.0, 0.5, c.teensy.orientation_noise_rad, error) ||
            !get_double(*sim, "yaw_drift_rad_s", "sim.", -0.1, 0.1, c.teensy.yaw_drift_rad_s, error))
            return false;
        uint32_t seed = static_cast<uint32_t>(c.teensy.noise_seed);
        if (!get_int<uint32_t>(*sim, "noise_seed", "sim.", 0, UINT32_MAX, seed, error))
            return false;
        c.teensy.noise_seed = seed;
    }
    if (auto rec = root["recovery"].as_table()) {
        // Share caracarad's recovery keys so one file describes both sides.
        if (auto v = (*rec)["unbind_path"].value<std::string>())
            c.unbind_path = *v;
        if (auto v = (*rec)["bind_path"].value<std::string>())
            c.bind_path = *v;
        if (auto v = (*rec)["driver_id"].value<std::string>())
            c.driver_id = *v;
    }
    if (auto spi = root["spi"].as_table()) {
        if (auto d = (*spi)["device"].value<std::string>())
            c.spi_device = *d;
    }
    if (auto arr = root["thruster"].as_array()) {
        c.thrusters.clear();
        for (size_t i = 0; i < arr->size(); ++i) {
            auto t = (*arr)[i].as_table();
            const std::string where = "thruster[" + std::to_string(i) + "].";
            if (!t) {
                error = where + ": must be a table";
                return false;
            }
            ThrusterSpec s;
            if (!get_int<uint8_t>(*t, "address", where, 0x10, 0xEE, s.mt, error))
                return false;
            if (s.mt & 1) {
                error = where + "address: must be the even write address byte";
                return false;
            }
            if (auto v = (*t)["variant"].value<std::string>()) {
                if (*v == "seabotix")
                    s.variant = ThrusterVariant::SeaBotix;
                else if (*v == "legacy")
                    s.variant = ThrusterVariant::Legacy;
                else {
                    error = where + "variant: must be \"seabotix\" or \"legacy\"";
                    return false;
                }
            }
            uint16_t mux = 0;
            if (t->contains("mux_address")) {
                if (!get_int<uint16_t>(*t, "mux_address", where, 0x70, 0x77, mux, error))
                    return false;
                s.mux_addr = mux;
            }
            if (!get_int<uint8_t>(*t, "mux_channel", where, 0, 3, s.mux_channel, error))
                return false;
            if (auto b = (*t)["brushless"].value<bool>())
                s.brushless = *b;
            c.thrusters.push_back(s);
        }
    }
    if (std::string e = parse_vehicle(root, c.vehicle); !e.empty()) {
        error = e;
        return false;
    }
    out = std::move(c);
    return true;
}

bool load_sim_config(const std::string& path, SimConfig& out, std::string& error) {
    std::ifstream f(path);
    if (!f) {
        error = "cannot read " + path;
        return false;
    }
    std::stringstream ss;
    ss << f.rdbuf();
    if (!parse_sim_config(ss.str(), out, error)) {
        error = path + ": " + error;
        return false;
    }
    return true;
}

} // namespace caracara::sim
