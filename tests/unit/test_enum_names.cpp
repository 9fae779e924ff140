// Every enum's names (core/enum_names.hpp): each value the enum declares has one name, each name
// reads back to its value, no two values share a name. The enum's own values are found by the
// compiler (an enumerator prints by name in __PRETTY_FUNCTION__, any other value as a cast), so a
// value added to an enum without a name in its table fails here; and every table in the sources
// is found by reading them, so a table added without being listed here fails too.
#include "core/budget.hpp"
#include "core/bus_scan_report.hpp"
#include "core/config.hpp"
#include "core/direction_judgement.hpp"
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
#include "daemon/teensy/teensy_link_watch.hpp"
#include "drivers/platform/io_error.hpp"
#include "drivers/protocol/seabotix.hpp"
#include "drivers/protocol/teensy_codec.hpp"
#include "sim/i2c_bus_model.hpp"
#include "sim/teensy_frame_record.hpp"
#include "sim/teensy_model.hpp"
#include "tests/catch.hpp"
#include "tools/bridge/pilot_seat.hpp"
#include "tools/ros/command_refusal.hpp"
#include "tools/ros/ros_conventions.hpp"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
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

// Every EnumNames table, by the enum's name as its specialisation spells it.
struct Table {
    std::string name;
    void (*check)(const char*);
};
#define CARACARA_TABLE(E) Table{#E, &check_names<E>}
const std::vector<Table> kTables{
    CARACARA_TABLE(BudgetError),
    CARACARA_TABLE(BudgetPolicy),
    CARACARA_TABLE(ScanVerdict),
    CARACARA_TABLE(DirectionVerdict),
    CARACARA_TABLE(dive::EventKind),
    CARACARA_TABLE(dive::ReadError),
    CARACARA_TABLE(FailsafeAction),
    CARACARA_TABLE(FailsafeCondition),
    CARACARA_TABLE(MixError),
    CARACARA_TABLE(frames::PilotAxis),
    CARACARA_TABLE(frames::WorldFrame),
    CARACARA_TABLE(PacketError),
    CARACARA_TABLE(PreflightItem),
    CARACARA_TABLE(SafetyState),
    CARACARA_TABLE(KillSource),
    CARACARA_TABLE(SafetyError),
    CARACARA_TABLE(Status),
    CARACARA_TABLE(Variant),
    CARACARA_TABLE(BusState),
    CARACARA_TABLE(TeensyLoss),
    CARACARA_TABLE(SchedPolicy),
    CARACARA_TABLE(IoError),
    CARACARA_TABLE(CodecError),
    CARACARA_TABLE(Fault),
    CARACARA_TABLE(LegacySoftware),
    CARACARA_TABLE(MaxPowerMeaning),
    CARACARA_TABLE(teensy::TeensyError),
    CARACARA_TABLE(sim::I2cBusModel::Hang),
    CARACARA_TABLE(sim::TeensyCommand),
    CARACARA_TABLE(sim::TeensyFrameOutcome),
    CARACARA_TABLE(sim::TeensyTaskState),
    CARACARA_TABLE(bridge::SeatAction),
    CARACARA_TABLE(bridge::SeatChange),
    CARACARA_TABLE(ros::CommandRefusal),
    CARACARA_TABLE(ros::RangeLayout),
    CARACARA_TABLE(ros::WrenchUnits),
};
#undef CARACARA_TABLE

// Every `struct EnumNames<E>` specialisation in the sources, by E as written there.
std::multiset<std::string> tables_in_sources() {
    namespace fs = std::filesystem;
    const std::regex specialisation(R"(struct\s+EnumNames\s*<\s*([A-Za-z_][\w:]*)\s*>)");
    std::multiset<std::string> found;
    for (const char* top : {"core", "drivers", "daemon", "dbus", "sim", "tools", "bench", "fuzz"}) {
        const fs::path dir = fs::path(CARACARA_SOURCE_DIR) / top;
        if (!fs::exists(dir))
            continue;
        for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir)) {
            const std::string ext = e.path().extension().string();
            if (!e.is_regular_file() || (ext != ".hpp" && ext != ".h" && ext != ".cpp"))
                continue;
            std::ifstream in(e.path());
            const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            for (std::sregex_iterator m(text.begin(), text.end(), specialisation), end; m != end; ++m)
                found.insert((*m)[1].str());
        }
    }
    return found;
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
    for (const Table& t : kTables)
        t.check(t.name.c_str());
}

TEST_CASE("every table in the sources is checked here, and each only once") {
    const std::multiset<std::string> in_sources = tables_in_sources();
    REQUIRE(in_sources.count("Status") == 1); // the sources were found and read
    std::multiset<std::string> listed;
    for (const Table& t : kTables)
        listed.insert(t.name);
    for (const std::string& name : in_sources) {
        INFO("EnumNames<" + name + "> is in the sources: add it to kTables");
        CHECK(listed.count(name) == 1);
        CHECK(in_sources.count(name) == 1);
    }
    for (const std::string& name : listed) {
        INFO(name + " is listed but no EnumNames<" + name + "> is in the sources (spelled as there?)");
        CHECK(in_sources.count(name) == 1);
    }
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
