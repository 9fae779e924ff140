#include "tools/ros/vehicle_diagnostics.hpp"

#include "core/clock.hpp"
#include "tools/ros/mirror_values.hpp"
#include "tools/ros/ros_conventions.hpp"

#include <cstdio>
#include <string>
#include <utility>

namespace caracara::ros {

using client::Props;
using client::Value;

namespace {
constexpr uint64_t kRefusalWarnNs = 10'000'000'000; // how long a refused command keeps "ros commands" at WARN
} // namespace

VehicleDiagnostics::VehicleDiagnostics(DdsParticipant& dds, const client::ObjectMirror& mirror, const RosConfig& config,
                                       const CommandRecord& commands, const SpokenDistro& distro,
                                       const DistroDetector* detector, const RangeSubscribers& range_subscribers)
    : mirror_(mirror), config_(config), commands_(commands), distro_(distro), detector_(detector),
      range_subscribers_(range_subscribers),
      writer_(dds.writer(&diagnostic_msgs_msg_dds__DiagnosticArray__desc, "/diagnostics", Profile::Default)) {}

std::vector<uint8_t> VehicleDiagnostics::levels() const {
    std::vector<uint8_t> out;
    for (unsigned i = 0; i < kThrusterJoints; ++i) {
        const Props& p = props(kThrusterPathPrefix + std::to_string(i), caracara::dbus::kThrusterIface);
        out.push_back(!prop(p, "Online").boolean() ? 2 : prop(p, "Faults").items.empty() ? 0 : 1);
    }
    const std::string bus = prop(props(caracara::dbus::kBusPath, caracara::dbus::kBusIface), "State").s;
    out.push_back(bus == "lost" ? 2 : bus == "ok" ? 0 : 1);
    out.push_back(prop(props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface), "Online").boolean() ? 0 : 2);
    const Props& v = props(caracara::dbus::kRootPath, caracara::dbus::kVehicleIface);
    out.push_back(prop(v, "Failsafes").items.empty() ? 0 : 1);
    const std::string state = prop(v, "State").s;
    out.push_back(state == "fault" ? 2 : state == "ready" || state == "arming" ? 0 : 1);
    // The ROS commands: WARN while a refusal is recent, so a monitor shows it, then OK again.
    const uint64_t last = commands_.last_refusal_ns();
    out.push_back(last && monotonic_ns() < last + kRefusalWarnNs ? 1 : 0);
    // The distro: WARN while peers of both are about (some of them cannot read what is sent).
    out.push_back(detector_ && detector_->peers(RangeLayout::Humble) && detector_->peers(RangeLayout::Jazzy) ? 1 : 0);
    out.push_back(range_subscribers_.warn() ? 1 : 0); // a Range subscriber cannot read what is written
    return out;
}

void VehicleDiagnostics::write() {
    struct Status {
        uint8_t level;
        std::string name, message, hardware_id;
        std::vector<std::pair<std::string, std::string>> values;
    };
    static const char* const kLevel[] = {"OK", "WARN", "ERROR"};
    const std::vector<uint8_t> lv = levels();
    std::vector<Status> st;
    const auto num = [](const Value& v) {
        char b[32];
        std::snprintf(b, sizeof b, "%g", v.number());
        return std::string(b);
    };
    for (unsigned i = 0; i < kThrusterJoints; ++i) {
        const Props& p = props(kThrusterPathPrefix + std::to_string(i), caracara::dbus::kThrusterIface);
        std::string faults;
        for (const Value& f : prop(p, "Faults").items)
            faults += (faults.empty() ? "" : ",") + f.s;
        st.push_back({lv[i], "caracara: " + thruster_joint_name(i),
                      lv[i] == 2 ? "unreachable" : faults.empty() ? "ok" : "faults: " + faults,
                      "seabotix@0x" + [&] { char b[8]; std::snprintf(b, sizeof b, "%02x", static_cast<unsigned>(prop(p, "Address").unsigned_integer())); return std::string(b); }(),
                      {{"ordered value", std::to_string(prop(p, "OrderedValue").integer())},
                       {"actual speed", std::to_string(prop(p, "ActualSpeed").unsigned_integer())},
                       {"current A", num(prop(p, "Current"))}, {"temperature C", num(prop(p, "Temperature"))},
                       {"faults", faults}, {"orders sent", std::to_string(prop(p, "OrdersSent").unsigned_integer())},
                       {"order failures", std::to_string(prop(p, "OrderFailures").unsigned_integer())},
                       {"last error", prop(p, "LastError").s}}});
    }
    const Props& b = props(caracara::dbus::kBusPath, caracara::dbus::kBusIface);
    st.push_back({lv[kThrusterJoints], "caracara: i2c bus", prop(b, "State").s, prop(b, "Device").s,
                  {{"transactions", std::to_string(prop(b, "Transactions").unsigned_integer())},
                   {"errors", std::to_string(prop(b, "Errors").unsigned_integer())},
                   {"recoveries", std::to_string(prop(b, "Recoveries").unsigned_integer())},
                   {"last error", prop(b, "LastError").s}}});
    const Props& t = props(caracara::dbus::kTeensyPath, caracara::dbus::kTeensyIface);
    st.push_back({lv[kThrusterJoints + 1], "caracara: teensy", prop(t, "Online").boolean() ? "online" : "offline", "teensy",
                  {{"frames", std::to_string(prop(t, "Frames").unsigned_integer())},
                   {"busy retries", std::to_string(prop(t, "BusyRetries").unsigned_integer())},
                   {"link errors", std::to_string(prop(t, "LinkErrors").unsigned_integer())}}});
    const Props& v = props(caracara::dbus::kRootPath, caracara::dbus::kVehicleIface);
    Status fs{lv[kThrusterJoints + 2], "caracara: failsafes", "", "caracarad", {}};
    for (const Value& f : prop(v, "Failsafes").items) // (condition, action, thruster)
        if (f.items.size() == 3)
            fs.values.push_back({f.items[0].s, f.items[1].s + (f.items[2].integer() >= 0 ? " thruster " + std::to_string(f.items[2].integer()) : "")});
    fs.message = fs.values.empty() ? "none active" : std::to_string(fs.values.size()) + " active";
    st.push_back(std::move(fs));
    st.push_back({lv[kThrusterJoints + 3], "caracara: vehicle", prop(v, "State").s, "caracarad",
                  {{"kill source", prop(v, "KillSource").s}, {"profile", prop(v, "Profile").s},
                   {"controller", prop(v, "Controller").s}, {"budget limit", std::to_string(prop(v, "BudgetLimit").integer())}}});
    const uint64_t now = monotonic_ns();
    const std::string holder = commands_.holder(now);
    Status cs{lv[kThrusterJoints + 4], "caracara: ros commands",
              !config_.commands ? "off (kill only)" : holder.empty() ? "no writer holds the vehicle" : "held by writer " + holder,
              "caracara-ros",
              {{"holder", holder}, {"command timeout ms", std::to_string(commands_.timeout_ms())},
               {"refused", std::to_string(commands_.refusals())}}};
    for (const auto& n : EnumNames<CommandRefusal>::table)
        cs.values.push_back({"refused " + std::string(n.name), std::to_string(commands_.refusals(n.value))});
    cs.values.push_back({"last refusal", commands_.last_refusal()});
    st.push_back(std::move(cs));
    const auto peers = [&](RangeLayout d) { return detector_ ? std::to_string(detector_->peers(d)) : std::string("not read"); };
    st.push_back({lv[kThrusterJoints + 5], "caracara: ros distro", std::string(name_of(distro_.layout)) + ": " + distro_.why,
                  "caracara-ros",
                  {{"speaking", std::string(name_of(distro_.layout))}, {"why", distro_.why},
                   {"humble peers", peers(RangeLayout::Humble)}, {"jazzy peers", peers(RangeLayout::Jazzy)}}});
    st.push_back({lv[kThrusterJoints + 6], "caracara: ros range layout",
                  std::string(name_of(range_subscribers_.layout())) + ": " + range_subscribers_.why(), "caracara-ros",
                  range_subscribers_.values()});
    std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>> kvs(st.size());
    std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> out;
    for (std::size_t i = 0; i < st.size(); ++i) {
        for (auto& [k, val] : st[i].values)
            kvs[i].push_back({msg_str(k), msg_str(val)});
        const auto n = static_cast<uint32_t>(kvs[i].size());
        out.push_back({st[i].level, msg_str(st[i].name), msg_str(st[i].message), msg_str(st[i].hardware_id),
                       {n, n, kvs[i].data(), false}});
    }
    const auto n = static_cast<uint32_t>(out.size());
    static const std::string kNoFrame; // diagnostics have no frame; header() keeps a pointer into it
    diagnostic_msgs_msg_dds__DiagnosticArray_ a{header(kNoFrame), {n, n, out.data(), false}};
    dds_write(writer_, &a);
    if (lv != last_levels_)
        for (std::size_t i = 0; i < lv.size() && i < st.size(); ++i)
            if (last_levels_.size() != lv.size() || last_levels_[i] != lv[i])
                std::fprintf(stderr, "caracara-ros: %s: %s (%s)\n", st[i].name.c_str(), kLevel[lv[i]], st[i].message.c_str());
    last_levels_ = lv;
}

} // namespace caracara::ros
