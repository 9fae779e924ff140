#include "tools/caracaractl/render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <ctime>
#include <numbers>
#include <vector>

namespace caracara::ctl {

using namespace caracara::client; // the vehicle's D-Bus client (tools/client)

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

const Value& prop(const Props& props, const char* name) {
    static const Value none;
    auto it = props.find(name);
    return it == props.end() ? none : it->second;
}

const Props* find_props(const Objects& objects, const std::string& path, const char* iface) {
    auto o = objects.find(path);
    if (o == objects.end())
        return nullptr;
    auto i = o->second.find(iface);
    return i == o->second.end() ? nullptr : &i->second;
}

std::vector<const Props*> thrusters(const Objects& objects) {
    std::vector<const Props*> out;
    for (const auto& [path, ifaces] : objects)
        if (auto i = ifaces.find(kThrusterIface); i != ifaces.end())
            out.push_back(&i->second);
    std::sort(out.begin(), out.end(), [](const Props* a, const Props* b) {
        return prop(*a, "Index").unsigned_integer() < prop(*b, "Index").unsigned_integer();
    });
    return out;
}

std::string hex_byte(const Value& v) { return strf("0x%02X", static_cast<unsigned>(v.unsigned_integer() & 0xFF)); }

// "a, b, c" of the items of an array, each formatted by `fn`; `none` when empty.
template <typename F>
std::string join(const Value& list, const char* separator, F fn, const char* none = "none") {
    std::string out;
    for (const Value& item : list.items)
        out += (out.empty() ? "" : separator) + fn(item);
    return out.empty() ? none : out;
}

std::string or_dash(const std::string& s) { return s.empty() ? "-" : s; }

void key_line(std::ostream& out, std::string_view key, const std::string& value) {
    constexpr size_t kKeyWidth = 15;
    out << std::string(key.size() < kKeyWidth ? kKeyWidth - key.size() : 0, ' ') << key << ": " << value << '\n';
}

void print_table(std::ostream& out, const std::vector<std::vector<std::string>>& rows) {
    std::vector<size_t> width;
    for (const auto& row : rows)
        for (size_t c = 0; c < row.size(); ++c) {
            width.resize(std::max(width.size(), row.size()));
            width[c] = std::max(width[c], row[c].size());
        }
    for (const auto& row : rows) {
        std::string line = "  ";
        for (size_t c = 0; c < row.size(); ++c)
            line += c + 1 < row.size() ? row[c] + std::string(width[c] - row[c].size() + 2, ' ') : row[c];
        out << line << '\n';
    }
}

void print_vehicle(std::ostream& out, const Props& v) {
    const std::string state = prop(v, "State").s;
    const std::string source = prop(v, "KillSource").s;
    std::string shown = state == "killed" || !source.empty() ? state + " (source: " + or_dash(source) + ")" : state;
    if (source == "start")
        shown += "; every start comes up killed: `caracaractl clear-kill` arms it";
    key_line(out, "State", shown);
    // (condition, action, thruster) of each active failsafe.
    key_line(out, "Failsafes", join(prop(v, "Failsafes"), ", ", [](const Value& f) {
        if (f.items.size() != 3)
            return render(f);
        const int64_t t = f.items[2].integer();
        return f.items[0].s + " " + f.items[1].s + (t >= 0 ? strf(" (thruster %lld)", static_cast<long long>(t)) : "");
    }, "none"));
    const std::string controller = prop(v, "Controller").s;
    key_line(out, "Controller", controller.empty() ? "none" : controller);
    // (thruster, value); a daemon without the property shows none.
    const Value& test = prop(v, "MotorTest");
    const int64_t tested = test.items.size() == 2 ? test.items[0].integer() : -1;
    key_line(out, "Motor test", tested < 0 ? std::string("none")
                                           : strf("thruster %lld at %lld", static_cast<long long>(tested),
                                                  static_cast<long long>(test.items[1].integer())));
    auto values = [](const Value& list) { return join(list, " ", [](const Value& x) { return render(x); }); };
    key_line(out, "Motor values", values(prop(v, "MotorValues")));
    key_line(out, "Requested", values(prop(v, "RequestedValues")));
    const int64_t limit = prop(v, "BudgetLimit").integer();
    key_line(out, "Budget",
             (limit ? strf("limit %lld", static_cast<long long>(limit)) : std::string("no motor running")) + ", " +
                 (prop(v, "Saturated").boolean() ? "saturated" : "not saturated") + ", policy " +
                 or_dash(prop(v, "BudgetPolicy").s));
    key_line(out, "Profile", or_dash(prop(v, "Profile").s) + strf(" (thrust x %g)", prop(v, "ProfileFactor").number()));
    const Value& leds = prop(v, "Leds");
    key_line(out, "LEDs",
             leds.items.size() == 3 ? strf("red %llu, green %llu, blue %llu",
                                           static_cast<unsigned long long>(leds.items[0].unsigned_integer()),
                                           static_cast<unsigned long long>(leds.items[1].unsigned_integer()),
                                           static_cast<unsigned long long>(leds.items[2].unsigned_integer()))
                                    : std::string("unknown"));
    const int64_t age = prop(v, "CommandAgeMs").integer();
    key_line(out, "Command age", age < 0 ? std::string("no command yet") : strf("%lld ms", static_cast<long long>(age)));
    key_line(out, "Timeouts",
             strf("command %llu ms, arming delay %llu ms",
                  static_cast<unsigned long long>(prop(v, "CommandTimeoutMs").unsigned_integer()),
                  static_cast<unsigned long long>(prop(v, "ArmingDelayMs").unsigned_integer())));
    const double rate = prop(v, "LoopRateHz").number();
    key_line(out, "Loop rate", rate > 0 ? strf("%g Hz", rate) : std::string("as fast as the bus allows"));
    key_line(out, "Cycles", render(prop(v, "Cycles")));
}

void print_thrusters(std::ostream& out, const std::vector<const Props*>& list) {
    std::vector<std::vector<std::string>> rows = {{"#", "ADDRESS", "VARIANT", "ONLINE", "ORDERED", "SPEED", "ACTUAL",
                                                   "CURRENT", "TEMP", "FAULTS", "NACKS", "TIMEOUTS", "BAD",
                                                   "LAST ERROR"}};
    for (const Props* t : list) {
        std::string address = hex_byte(prop(*t, "Address"));
        if (prop(*t, "MuxChannel").integer() >= 0 && prop(*t, "MuxChannel").kind != Value::Kind::None)
            address += strf("@mux0x%02llX:%lld", static_cast<unsigned long long>(prop(*t, "MuxAddress").unsigned_integer()),
                            static_cast<long long>(prop(*t, "MuxChannel").integer()));
        rows.push_back({render(prop(*t, "Index")), address, prop(*t, "Variant").s + (prop(*t, "Reversed").boolean() ? " (rev)" : ""),
                        prop(*t, "Online").boolean() ? "yes" : "no", render(prop(*t, "OrderedValue")),
                        hex_byte(prop(*t, "OrderedSpeed")), hex_byte(prop(*t, "ActualSpeed")),
                        strf("%.1f A", prop(*t, "Current").number()), strf("%.1f C", prop(*t, "Temperature").number()),
                        join(prop(*t, "Faults"), ",", [](const Value& f) { return f.s; }, "-"),
                        render(prop(*t, "Nacks")), render(prop(*t, "Timeouts")), render(prop(*t, "BadReplies")),
                        or_dash(prop(*t, "LastError").s)});
    }
    print_table(out, rows);
    // The faults someone must act on, said in words under the table.
    for (const Props* t : list)
        for (const Value& f : prop(*t, "Faults").items)
            if (f.s == "water-detect" || f.s == "overtemp")
                out << "Warning: thruster " << render(prop(*t, "Index")) << ": " << f.s << '\n';
}

void print_teensy(std::ostream& out, const Props& t) {
    const Value& o = prop(t, "Orientation");
    if (o.items.size() == 3) {
        // The Teensy's angles in a pilot's words (docs/frames.md): each signed, with what + means.
        const double d[3] = {o.items[0].number() * kDegPerRad, o.items[1].number() * kDegPerRad,
                             o.items[2].number() * kDegPerRad};
        const std::string text = strf("heading %.1f\u00b0 (clockwise), pitch %+.1f\u00b0 (nose up), roll %+.1f\u00b0 "
                                      "(right side down)", d[0], d[1], d[2]);
        key_line(out, "Orientation", text);
    }
    key_line(out, "Distances", join(prop(t, "Distances"), ", ", [](const Value& d) { return render(d) + " mm"; }));
    key_line(out, "Servos", join(prop(t, "Servos"), ", ", [](const Value& s) { return render(s) + "\u00b0"; }));
    key_line(out, "Task", or_dash(prop(t, "Task").s));
    key_line(out, "Link", render(prop(t, "Frames")) + " frames, " + render(prop(t, "BusyRetries")) + " busy retries, " +
                              render(prop(t, "LinkErrors")) + " link errors");
}

void print_bus(std::ostream& out, const Props& b) {
    key_line(out, "State", or_dash(prop(b, "State").s));
    key_line(out, "Transactions", render(prop(b, "Transactions")));
    const std::string last = prop(b, "LastError").s;
    key_line(out, "Errors", render(prop(b, "Errors")) + (last.empty() ? "" : ", last: " + last));
}

} // namespace

std::string strf(const char* format, ...) {
    va_list ap;
    va_start(ap, format);
    va_list copy;
    va_copy(copy, ap);
    const int n = std::vsnprintf(nullptr, 0, format, copy);
    va_end(copy);
    std::string out(n > 0 ? static_cast<size_t>(n) : 0, '\0');
    if (n > 0)
        std::vsnprintf(out.data(), out.size() + 1, format, ap);
    va_end(ap);
    return out;
}

std::string render(const Value& v) {
    auto list = [&](char open, char close) {
        std::string out(1, open);
        for (size_t i = 0; i < v.items.size(); ++i)
            out += (i ? "," : "") + render(v.items[i]);
        return out + close;
    };
    switch (v.kind) {
    case Value::Kind::None: return "?";
    case Value::Kind::Bool: return v.b ? "true" : "false";
    case Value::Kind::Signed: return std::to_string(v.i);
    case Value::Kind::Unsigned: return std::to_string(v.u);
    case Value::Kind::Double: return strf("%g", v.d);
    case Value::Kind::String:
        return v.s.empty() || v.s.find_first_of(" \t\"") != std::string::npos ? "\"" + v.s + "\"" : v.s;
    case Value::Kind::Array: return list('[', ']');
    case Value::Kind::Struct: return list('(', ')');
    }
    return "?";
}

std::string render_property(std::string_view name, const Value& v) {
    if (name == "Address" || name == "OrderedSpeed" || name == "ActualSpeed")
        return hex_byte(v);
    if (name == "Orientation" && v.items.size() == 3)
        return strf("(%.1f,%.1f,%.1f)deg", v.items[0].number() * kDegPerRad, v.items[1].number() * kDegPerRad,
                    v.items[2].number() * kDegPerRad);
    return render(v);
}

std::string object_label(std::string_view path) {
    const std::string_view root = kRootPath;
    if (path == root)
        return "vehicle";
    if (path.starts_with(root) && path.size() > root.size() + 1 && path[root.size()] == '/')
        return std::string(path.substr(root.size() + 1));
    return std::string(path);
}

std::string timestamp_now() {
    timespec ts{};
    clock_gettime(CLOCK_REALTIME, &ts);
    tm local{};
    localtime_r(&ts.tv_sec, &local);
    char hms[16];
    std::strftime(hms, sizeof hms, "%H:%M:%S", &local);
    return strf("%s.%03ld", hms, ts.tv_nsec / 1'000'000);
}

void print_status(std::ostream& out, const Objects& objects) {
    if (const Props* v = find_props(objects, kRootPath, kVehicleIface)) {
        out << "Vehicle:\n";
        print_vehicle(out, *v);
    }
    if (auto list = thrusters(objects); !list.empty()) {
        out << "\nThrusters:\n";
        print_thrusters(out, list);
    }
    if (const Props* t = find_props(objects, kTeensyPath, kTeensyIface)) {
        out << "\nTeensy: " << (prop(*t, "Online").boolean() ? "online" : "offline") << '\n';
        print_teensy(out, *t);
    } else {
        out << "\nTeensy: not present\n";
    }
    if (const Props* b = find_props(objects, kBusPath, kBusIface)) {
        out << "\nI2C bus: " << or_dash(prop(*b, "Device").s) << '\n';
        print_bus(out, *b);
    }
}

std::string summary_line(const Objects& objects) {
    std::string line;
    if (const Props* v = find_props(objects, kRootPath, kVehicleIface)) {
        line += "vehicle";
        for (const char* name : {"State", "KillSource", "Controller", "MotorValues", "Saturated", "Leds"})
            line += std::string(" ") + name + "=" + render_property(name, prop(*v, name));
    }
    const auto list = thrusters(objects);
    const auto online = std::count_if(list.begin(), list.end(), [](const Props* t) { return prop(*t, "Online").boolean(); });
    line += strf(" | thrusters online %ld/%zu", static_cast<long>(online), list.size());
    if (const Props* t = find_props(objects, kTeensyPath, kTeensyIface))
        line += " | teensy Online=" + render(prop(*t, "Online")) + " Task=" + render(prop(*t, "Task")) +
                " Orientation=" + render_property("Orientation", prop(*t, "Orientation"));
    if (const Props* b = find_props(objects, kBusPath, kBusIface))
        line += " | bus State=" + render(prop(*b, "State"));
    return line;
}

} // namespace caracara::ctl
