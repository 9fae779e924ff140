#include "core/thruster_table.hpp"

#include "core/hex.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace caracara {

namespace {

std::string segment_name(const ThrusterConfig& t) {
    if (!t.mux)
        return "on the main bus";
    return "behind mux " + hex(t.mux->addr7) + " channel " + std::to_string(t.mux->channel);
}

// Returns false when this thruster has an error (so the set checks skip it).
bool parse_thruster(Checker& c, const toml::table& t, std::size_t i, ThrusterConfig& out) {
    const std::string p = "thruster[" + std::to_string(i) + "].";
    const std::size_t before = c.errors.size();
    // "brushless" describes the simulated motor (caracara-sim reads the same file).
    c.only_keys(t, p, {"address", "variant", "info", "mux_address", "mux_channel", "reversed", "brushless", "position", "direction"});

    const toml::node* an = t.get("address");
    if (!an) {
        c.fail(p + "address", "missing (the thruster's 8-bit write address byte, e.g. 0x52)", &t);
    } else if (const auto* iv = an->as_integer(); !iv) {
        c.fail(p + "address", "must be an integer, got " + written(*an), an);
    } else {
        const int64_t v = iv->get();
        if (v < 0 || v > 0xFF)
            c.fail(p + "address", "must be an 8-bit address byte (MT), got " + hex(v), an);
        else if (v & 1)
            c.fail(p + "address",
                   hex(v) + " is a read address byte; must be even (the write byte, e.g. " + hex(v - 1) + ")", an);
        else if (!is_valid_mt(static_cast<uint8_t>(v)))
            c.fail(p + "address",
                   hex(v) + " is a reserved I2C address (7-bit " + hex(v >> 1) + "); must be between 0x10 and 0xEE",
                   an);
        else
            out.mt = static_cast<uint8_t>(v);
    }

    std::string variant;
    if (c.string(t, p, "variant", variant)) {
        if (auto v = parse_variant(variant))
            out.variant = *v;
        else
            c.fail(p + "variant", "must be \"seabotix\" or \"legacy\", got \"" + variant + "\"", t.get("variant"));
    }
    c.integer(t, p, "info", 0, 255, out.info);
    c.boolean(t, p, "reversed", out.reversed);
    bool brushless = true;
    c.boolean(t, p, "brushless", brushless);

    const toml::node* mux_addr = t.get("mux_address");
    const toml::node* mux_chan = t.get("mux_channel");
    if (mux_addr && !mux_chan) {
        c.fail(p + "mux_channel", "missing: mux_address and mux_channel go together", mux_addr);
    } else if (!mux_addr && mux_chan) {
        c.fail(p + "mux_address", "missing: mux_address and mux_channel go together", mux_chan);
    } else if (mux_addr && mux_chan) {
        MuxRoute route;
        bool good = true;
        const auto* iv = mux_addr->as_integer();
        if (iv && iv->get() >= 0xE0 && iv->get() <= 0xEE && (iv->get() & 1) == 0) {
            c.fail(p + "mux_address",
                   hex(iv->get()) + " looks like an 8-bit address byte; use the 7-bit address " +
                       hex(iv->get() >> 1) + " (PCA9544A: 0x70..0x77)",
                   mux_addr);
            good = false;
        } else {
            good = c.integer(t, p, "mux_address", kMuxAddrMin, kMuxAddrMax, route.addr7,
                             "a 7-bit PCA9544A address between 0x70 and 0x77 (112..119)");
        }
        good = c.integer(t, p, "mux_channel", 0, kMuxChannels - 1, route.channel) && good;
        if (good)
            out.mux = route;
    }
    return c.errors.size() == before;
}

void check_thruster_set(Checker& c, const std::array<ThrusterConfig, kMotorCount>& set,
                        const std::array<bool, kMotorCount>& valid) {
    auto name = [](std::size_t i) { return "thruster[" + std::to_string(i) + "]"; };
    for (const ThrusterConflict& k : thruster_conflicts(set, valid)) {
        const ThrusterConfig& t = set[k.thruster];
        if (k.kind == ThrusterConflict::Kind::MuxAddress) {
            c.fail(name(k.thruster) + ".address", hex(t.mt) + " (7-bit " + hex(mt_addr7(t.mt)) +
                                                      ") is the address of the multiplexer used by " + name(k.other));
            continue;
        }
        const ThrusterConfig& o = set[k.other];
        std::string why;
        if (!o.mux && !t.mux)
            why = "both are on the main bus";
        else if (o.mux && t.mux)
            why = "both are " + segment_name(o);
        else
            why = name(o.mux ? k.thruster : k.other) + " is on the main bus, which an enabled mux channel joins to " +
                  name(o.mux ? k.other : k.thruster) + "'s segment";
        c.fail(name(k.thruster) + ".address", hex(t.mt) + " is also the address of " + name(k.other) + "; " + why);
    }
}

} // namespace

void parse_thrusters(Checker& c, const toml::table& root, std::array<ThrusterConfig, kMotorCount>& out) {
    const toml::node* n = root.get("thruster");
    if (!n)
        return;  // the default vehicle
    const toml::array* arr = n->as_array();
    if (!arr || !arr->is_array_of_tables()) {
        c.fail("thruster", "must be an array of tables ([[thruster]] sections), got " + written(*n), n);
        return;
    }
    if (arr->size() != kMotorCount) {
        c.fail("thruster",
               "expected exactly " + std::to_string(kMotorCount) + " [[thruster]] sections (motors 0..7), got " +
                   std::to_string(arr->size()),
               n);
    }
    std::array<ThrusterConfig, kMotorCount> set{};
    std::array<bool, kMotorCount> valid{};
    for (std::size_t i = 0; i < arr->size(); ++i) {
        ThrusterConfig tc;
        const bool ok = parse_thruster(c, *(*arr)[i].as_table(), i, tc);
        if (i < kMotorCount) {
            set[i] = tc;
            valid[i] = ok;
        }
    }
    if (arr->size() != kMotorCount)
        return;
    check_thruster_set(c, set, valid);
    out = set;
}

void parse_mixing(Checker& c, const toml::table& t, MixMatrix& out) {
    c.only_keys(t, "mixing.", {"matrix"});
    const toml::node* n = t.get("matrix");
    if (!n)
        return;
    const toml::array* rows = n->as_array();
    if (!rows || rows->size() != kMotorCount) {
        c.fail("mixing.matrix",
               "must be an array of 8 rows (one per motor), got " +
                   (rows ? std::to_string(rows->size()) + " rows" : written(*n)),
               n);
        return;
    }
    MixMatrix m{};
    bool good = true;
    for (std::size_t i = 0; i < kMotorCount; ++i) {
        const std::string rk = "mixing.matrix[" + std::to_string(i) + "]";
        const toml::node& rn = *rows->get(i);
        const toml::array* row = rn.as_array();
        if (!row || row->size() != kAxisCount) {
            c.fail(rk,
                   "must be an array of 6 numbers (x, y, z, yaw, pitch, roll), got " +
                       (row ? std::to_string(row->size()) + " values" : written(rn)),
                   &rn);
            good = false;
            continue;
        }
        for (std::size_t j = 0; j < kAxisCount; ++j) {
            const toml::node& vn = *row->get(j);
            const std::string vk = rk + "[" + std::to_string(j) + "] (motor " + std::to_string(i) + ", " +
                                   std::string(axis_name(j)) + ")";
            double v = 0.0;
            if (const auto* iv = vn.as_integer())
                v = static_cast<double>(iv->get());
            else if (const auto* fv = vn.as_floating_point())
                v = fv->get();
            else {
                c.fail(vk, "must be a number, got " + written(vn), &vn);
                good = false;
                continue;
            }
            if (!std::isfinite(v) || v < -1.0 || v > 1.0) {
                c.fail(vk, "must be a number between -1 and 1, got " + written(vn), &vn);
                good = false;
                continue;
            }
            m[i][j] = v;
        }
    }
    if (good)
        out = m;
}

} // namespace caracara
