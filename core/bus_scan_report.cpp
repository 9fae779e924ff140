#include "core/bus_scan_report.hpp"

#include <algorithm>
#include <cstdio>

namespace caracara {

namespace {

std::string hex2(unsigned v) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02x", v & 0xFFu);
    return buf;
}

std::string where_text(const ScanDevice& d) { return segment_text(d.segment) + " at " + hex2(d.mt); }

std::string variant_text(const std::optional<Variant>& v) {
    return v ? std::string(variant_name(*v)) : std::string("no thruster");
}

int32_t find_device(const BusScanReport& r, const auto& pred) {
    for (std::size_t k = 0; k < r.devices.size(); ++k)
        if (r.devices[k].thruster < 0 && pred(r.devices[k]))
            return static_cast<int32_t>(k);
    return -1;
}

} // namespace

bool same_segment(const ScanSegment& a, const ScanSegment& b) {
    if (!a || !b)
        return !a && !b;
    return a->addr7 == b->addr7 && a->channel == b->channel;
}

std::string segment_text(const ScanSegment& s) {
    if (!s)
        return "trunk";
    return "mux " + hex2(s->addr7) + " channel " + std::to_string(s->channel);
}

bool BusScanReport::matches() const {
    const bool all_ok = std::all_of(thrusters.begin(), thrusters.end(),
                                    [](const ThrusterScan& t) { return t.verdict == ScanVerdict::Ok; });
    const bool none_unexpected =
        std::all_of(devices.begin(), devices.end(), [](const ScanDevice& d) { return d.thruster >= 0; });
    return all_ok && none_unexpected;
}

std::vector<uint8_t> scan_addresses(std::span<const ThrusterConfig> thrusters) {
    std::vector<uint8_t> out{default_mt(Variant::SeaBotix), default_mt(Variant::Legacy)};
    for (const ThrusterConfig& t : thrusters)
        out.push_back(t.mt);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::vector<ScanSegment> scan_segments(std::span<const ThrusterConfig> thrusters) {
    std::vector<uint16_t> muxes;
    for (const ThrusterConfig& t : thrusters)
        if (t.mux)
            muxes.push_back(t.mux->addr7);
    std::sort(muxes.begin(), muxes.end());
    muxes.erase(std::unique(muxes.begin(), muxes.end()), muxes.end());
    std::vector<ScanSegment> out{std::nullopt};
    for (uint16_t m : muxes)
        for (uint8_t ch = 0; ch < kMuxChannels; ++ch)
            out.push_back(MuxRoute{m, ch});
    return out;
}

bool add_scan_device(BusScanReport& report, const ScanDevice& device) {
    if (device.segment && std::any_of(report.devices.begin(), report.devices.end(), [&](const ScanDevice& d) {
            return !d.segment && d.mt == device.mt;
        }))
        return false;
    report.devices.push_back(device);
    return true;
}

void judge_bus_scan(std::span<const ThrusterConfig> thrusters, BusScanReport& report) {
    report.thrusters.assign(thrusters.size(), {});
    for (ScanDevice& d : report.devices)
        d.thruster = -1;
    // Where the configuration puts it, first, for every thruster: a moved one must not take
    // another's place.
    for (std::size_t i = 0; i < thrusters.size(); ++i) {
        const ThrusterConfig& t = thrusters[i];
        ThrusterScan& s = report.thrusters[i];
        s.device = find_device(report, [&](const ScanDevice& d) { return same_segment(d.segment, t.mux) && d.mt == t.mt; });
        if (s.device < 0)
            continue;
        ScanDevice& d = report.devices[static_cast<std::size_t>(s.device)];
        d.thruster = static_cast<int32_t>(i);
        if (d.variant == t.variant) {
            s.verdict = ScanVerdict::Ok;
            continue;
        }
        s.verdict = ScanVerdict::WrongVariant;
        s.advice = "answered as " + variant_text(d.variant) + " (revision " + std::to_string(d.revision) +
                   "), configured " + std::string(variant_name(t.variant)) + ": fit a " +
                   std::string(variant_name(t.variant)) + " controller or set variant = \"" +
                   variant_text(d.variant) + "\" in its [[thruster]] table";
    }
    for (std::size_t i = 0; i < thrusters.size(); ++i) {
        const ThrusterConfig& t = thrusters[i];
        ThrusterScan& s = report.thrusters[i];
        if (s.device >= 0)
            continue;
        s.device = find_device(report, [&](const ScanDevice& d) { return d.mt == t.mt; });
        if (s.device < 0) {
            const auto on_segment = [&](const ScanDevice& d) { return same_segment(d.segment, t.mux); };
            const int32_t first = find_device(report, on_segment);
            if (first >= 0 && std::count_if(report.devices.begin(), report.devices.end(), [&](const ScanDevice& d) {
                                  return d.thruster < 0 && on_segment(d);
                              }) == 1)
                s.device = first;
        }
        const std::string configured = segment_text(t.mux) + " at " + hex2(t.mt);
        if (s.device < 0) {
            s.verdict = ScanVerdict::Missing;
            s.advice = "nothing answered at " + configured +
                       " or anywhere else: check its cable, connector and power, then scan again";
            continue;
        }
        ScanDevice& d = report.devices[static_cast<std::size_t>(s.device)];
        d.thruster = static_cast<int32_t>(i);
        s.verdict = ScanVerdict::Moved;
        s.advice = "found on " + where_text(d) + ", configured " + configured + ": plug it back into " +
                   segment_text(t.mux) + " or change its [[thruster]] table";
        if (d.variant != t.variant)
            s.advice += "; it answered as " + variant_text(d.variant) + ", configured " + std::string(variant_name(t.variant));
    }
}

} // namespace caracara
