// One row of the preflight's go/no-go table (docs/commissioning.md, Preflight): which item, go
// or not, what was observed and, for a no-go, what to do about it.
#pragma once

#include "core/enum_names.hpp"

#include <array>
#include <cstdint>
#include <string>

namespace caracara {

enum class PreflightItem : uint8_t { Thruster, Bus, Teensy, KillSwitch, KillOutput, Config, Recorder, Failsafes, Clock };
template <>
struct EnumNames<PreflightItem> {
    static constexpr std::array<EnumName<PreflightItem>, 9> table{{
        {PreflightItem::Thruster, "thruster"},
        {PreflightItem::Bus, "bus"},
        {PreflightItem::Teensy, "teensy"},
        {PreflightItem::KillSwitch, "kill-switch"},
        {PreflightItem::KillOutput, "kill-output"},
        {PreflightItem::Config, "config"},
        {PreflightItem::Recorder, "recorder"},
        {PreflightItem::Failsafes, "failsafes"},
        {PreflightItem::Clock, "clock"},
    }};
};

struct PreflightRow {
    PreflightItem item = PreflightItem::Thruster;
    int32_t thruster = -1; // the thruster's number for PreflightItem::Thruster
    bool go = false;
    std::string observed;
    std::string advice; // what to do; "" for a go

    // "thruster-3", "bus", ...: the row's name on D-Bus and in caracaractl's table.
    std::string name() const {
        std::string n(name_of(item));
        return thruster < 0 ? n : n + "-" + std::to_string(thruster);
    }
};

} // namespace caracara
