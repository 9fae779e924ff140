// Every enum's names (core/enum_names.hpp): each value the enum declares has one name, each name
// reads back to its value, no two values share a name. The enum's own values are found by the
// compiler (an enumerator prints by name in __PRETTY_FUNCTION__, any other value as a cast), so a
// value added to an enum without a name in its table fails here.
#include "core/budget.hpp"
#include "core/bus_scan_report.hpp"
#include "core/config.hpp"
#include "core/dive_format.hpp"
#include "core/failsafe.hpp"
#include "core/frames.hpp"
#include "core/mixing.hpp"
#include "core/packet.hpp"
#include "core/preflight_row.hpp"
#include "core/safety_state.hpp"
#include "core/status.hpp"
#include "core/thruster_config.hpp"
#include "daemon/bus/bus_monitor.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/protocol/seabotix.hpp"
#include "drivers/protocol/teensy_codec.hpp"
#include "sim/i2c_bus_model.hpp"
#include "sim/teensy_frame_record.hpp"
#include "sim/teensy_model.hpp"
#include "tests/catch.hpp"
#include "tools/bridge/pilot_seat.hpp"

#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

using namespace caracara;

namespace {

// "[with auto V = caracara::KillSource::Switch]" for an enumerator, "... = (caracara::KillSource)9]" else.
template <auto V>
constexpr bool is_enumerator() {
    const std::string_view f = __PRETTY_FUNCTION__;
    const std::size_t at = f.rfind("= ");
    return at != std::string_view::npos && f[at + 2] != '(';
}

template <typename E, std::size_t... I>
std::vector<E> enumerators(std::index_sequence<I...>) {
    std::vector<E> out;
    ((is_enumerator<static_cast<E>(I)>() ? out.push_back(static_cast<E>(I)) : void()), ...);
    return out;
}

// The values 0..63 the enum declares (every enum here is smaller).
template <typename E>
std::vector<E> declared_values() {
    return enumerators<E>(std::make_index_sequence<64>{});
}

template <typename E>
void check_names(const char* what) {
    INFO(what);
    const std::vector<E> values = declared_values<E>();
    REQUIRE(!values.empty());
    CHECK(values.size() == EnumNames<E>::table.size());
    std::set<std::string_view> seen;
    for (E v : values) {
        const std::string_view name = name_of(v);
        INFO(std::string(what) + " value " + std::to_string(static_cast<int>(v)) + ": " + std::string(name));
        CHECK(name != "?");
        CHECK(!name.empty());
        CHECK(seen.insert(name).second);
        const std::optional<E> back = parse_name<E>(name);
        REQUIRE(back.has_value());
        CHECK(*back == v);
    }
    CHECK_FALSE(parse_name<E>("no-such-name").has_value());
}

} // namespace

TEST_CASE("the compiler tells an enumerator from another value") {
    CHECK(is_enumerator<KillSource::Switch>());
    CHECK_FALSE(is_enumerator<static_cast<KillSource>(60)>());
    CHECK(declared_values<BudgetPolicy>().size() == 2);
    // An enum that starts at 1 (a wire format's).
    CHECK(declared_values<dive::EventKind>().front() == dive::EventKind::State);
}

TEST_CASE("every enum's values have one name each, and each name reads back") {
    check_names<BudgetError>("BudgetError");
    check_names<BudgetPolicy>("BudgetPolicy");
    check_names<ScanVerdict>("ScanVerdict");
    check_names<dive::EventKind>("dive::EventKind");
    check_names<dive::ReadError>("dive::ReadError");
    check_names<FailsafeAction>("FailsafeAction");
    check_names<FailsafeCondition>("FailsafeCondition");
    check_names<MixError>("MixError");
    check_names<frames::PilotAxis>("frames::PilotAxis");
    check_names<frames::WorldFrame>("frames::WorldFrame");
    check_names<PacketError>("PacketError");
    check_names<PreflightItem>("PreflightItem");
    check_names<SafetyState>("SafetyState");
    check_names<KillSource>("KillSource");
    check_names<SafetyError>("SafetyError");
    check_names<Status>("Status");
    check_names<Variant>("Variant");
    check_names<BusState>("BusState");
    check_names<SchedPolicy>("SchedPolicy");
    check_names<IoError>("IoError");
    check_names<CodecError>("CodecError");
    check_names<Fault>("Fault");
    check_names<LegacySoftware>("LegacySoftware");
    check_names<MaxPowerMeaning>("MaxPowerMeaning");
    check_names<teensy::TeensyError>("teensy::TeensyError");
    check_names<sim::I2cBusModel::Hang>("sim::I2cBusModel::Hang");
    check_names<sim::TeensyFrameOutcome>("sim::TeensyFrameOutcome");
    check_names<sim::TeensyTaskState>("sim::TeensyTaskState");
    check_names<bridge::SeatAction>("bridge::SeatAction");
    check_names<bridge::SeatChange>("bridge::SeatChange");
}

TEST_CASE("names that are a contract keep their spelling") {
    // On D-Bus (State, KillSource, error names) and in the config.
    CHECK(name_of(SafetyState::PoweredOff) == "powered-off");
    CHECK(name_of(KillSource::Failsafe) == "failsafe");
    CHECK(name_of(Status::FailsafeActive) == "FailsafeActive");
    CHECK(name_of(FailsafeCondition::TeensyLinkLost) == "teensy-link-lost");
    CHECK(parse_name<BudgetPolicy>("reject") == BudgetPolicy::Reject);
    CHECK(parse_variant("legacy") == Variant::Legacy);
    CHECK_FALSE(parse_variant("Legacy").has_value()); // exact lowercase names only
}
