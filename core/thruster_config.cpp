#include "core/thruster_config.hpp"

#include "core/hex.hpp"

namespace caracara {

std::string_view variant_name(Variant v) {
    switch (v) {
    case Variant::SeaBotix: return "seabotix";
    case Variant::Legacy: return "legacy";
    }
    return "seabotix";
}

std::optional<Variant> parse_variant(std::string_view s) {
    if (s == "seabotix")
        return Variant::SeaBotix;
    if (s == "legacy")
        return Variant::Legacy;
    return std::nullopt;
}

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

std::string validate_thruster_set(std::span<const ThrusterConfig> set) {
    for (std::size_t i = 0; i < set.size(); ++i) {
        const std::string err = validate_thruster_config(set[i]);
        if (!err.empty())
            return "thruster " + std::to_string(i) + ": " + err;
    }
    for (std::size_t i = 0; i < set.size(); ++i) {
        const ThrusterConfig& a = set[i];
        const uint16_t a7 = mt_addr7(a.mt);
        for (const ThrusterConfig& m : set)
            if (m.mux && m.mux->addr7 == a7)
                return "thruster " + std::to_string(i) + ": address " + hex(a7) + " is a mux address";
        for (std::size_t j = i + 1; j < set.size(); ++j) {
            const ThrusterConfig& b = set[j];
            if (mt_addr7(b.mt) != a7)
                continue;
            const bool distinct_segments = a.mux && b.mux &&
                                           (a.mux->addr7 != b.mux->addr7 || a.mux->channel != b.mux->channel);
            if (!distinct_segments)
                return "thrusters " + std::to_string(i) + " and " + std::to_string(j) + " share address " + hex(a7) +
                       " on one bus segment";
        }
    }
    return {};
}

} // namespace caracara
