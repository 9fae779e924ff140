#include "core/thruster_config.hpp"

#include "core/hex.hpp"

namespace caracara {

std::string validate_thruster_config(const ThrusterConfig& cfg) {
    if (!is_valid_mt(cfg.mt))
        return "mt " + hex(cfg.mt) + " is not an even 8-bit write address in 0x10..0xee";
    if (cfg.mux) {
        if (!is_valid_mux_addr7(cfg.mux->addr7))
            return "mux address " + hex(cfg.mux->addr7) + " is not a PCA9544A address (0x70..0x77)";
        if (cfg.mux->channel >= kMuxChannels)
            return "mux channel " + std::to_string(cfg.mux->channel) + " is not 0..3";
    }
    return {};
}

std::vector<ThrusterConflict> thruster_conflicts(std::span<const ThrusterConfig> set, std::span<const bool> valid) {
    auto ok = [&](std::size_t i) { return valid.empty() || valid[i]; };
    std::vector<ThrusterConflict> out;
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (!ok(i))
            continue;
        const uint16_t a7 = mt_addr7(set[i].mt);
        for (std::size_t m = 0; m < set.size(); ++m)
            if (ok(m) && set[m].mux && set[m].mux->addr7 == a7) {
                out.push_back({ThrusterConflict::Kind::MuxAddress, i, m});
                break;
            }
    }
    for (std::size_t i = 0; i < set.size(); ++i) {
        for (std::size_t j = i + 1; j < set.size(); ++j) {
            if (!ok(i) || !ok(j) || mt_addr7(set[i].mt) != mt_addr7(set[j].mt))
                continue;
            const ThrusterConfig& a = set[i];
            const ThrusterConfig& b = set[j];
            // Separate segments: the driver enables one mux channel at a time. A thruster on the
            // trunk shares every segment, because an enabled channel joins its segment to the trunk.
            if (a.mux && b.mux && (a.mux->addr7 != b.mux->addr7 || a.mux->channel != b.mux->channel))
                continue;
            out.push_back({ThrusterConflict::Kind::SharedAddress, j, i});
        }
    }
    return out;
}

std::string validate_thruster_set(std::span<const ThrusterConfig> set) {
    for (std::size_t i = 0; i < set.size(); ++i) {
        const std::string err = validate_thruster_config(set[i]);
        if (!err.empty())
            return "thruster " + std::to_string(i) + ": " + err;
    }
    const auto conflicts = thruster_conflicts(set);
    if (conflicts.empty())
        return {};
    const ThrusterConflict& k = conflicts.front();
    const uint16_t a7 = mt_addr7(set[k.thruster].mt);
    if (k.kind == ThrusterConflict::Kind::MuxAddress)
        return "thruster " + std::to_string(k.thruster) + ": address " + hex(a7) + " is a mux address";
    return "thrusters " + std::to_string(k.other) + " and " + std::to_string(k.thruster) + " share address " + hex(a7) +
           " on one bus segment";
}

} // namespace caracara
