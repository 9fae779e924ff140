// caracaractl's side of the bus: the connection, one method-call helper that maps D-Bus errors
// to exit codes, and a generic decoder for property values.
#pragma once

#include "dbus/vehicle_names.hpp"
#include "drivers/sdbus/sdbus.hpp"
#include "tools/client/ssh_stderr.hpp"

#include <cstdint>
#include <functional>
#include <map>

#include <string>
#include <vector>

namespace caracara::client {

using caracara::dbus::kBusIface;
using caracara::dbus::kBusPath;
using caracara::dbus::kRootPath;
using caracara::dbus::kTeensyIface;
using caracara::dbus::kTeensyPath;
using caracara::dbus::kThrusterIface;
using caracara::dbus::kVehicleIface;
inline constexpr const char* kService = caracara::dbus::kBusName;

// Exit codes, as documented in --help.
enum Exit : int {
    kExitOk = 0,
    kExitRefused = 1,     // the daemon answered with an error
    kExitUsage = 2,       // bad command line; nothing was sent
    kExitUnavailable = 3, // caracarad not running, bus unreachable, no reply
    kExitDenied = 4,      // permission denied (the bus policy, or SSH refused the login)
};

// True when SIGINT or SIGTERM waits (blocked, for a signalfd): with -H, ssh is in caracaractl's
// process group and dies of the same Ctrl-C, so the connection may drop before the signal is read.
bool stop_signal_pending();

// Thrown for anything that ends the program early; main prints "caracaractl: <message>".
struct Failure {
    int code;
    std::string message;
};

// A decoded D-Bus value. Variants are unwrapped; arrays and dicts are Array (a dict's items are
// Struct key/value pairs); structs are Struct.
struct Value {
    enum class Kind { None, Bool, Signed, Unsigned, Double, String, Array, Struct };
    Kind kind = Kind::None;
    char code = 0; // the D-Bus type code ('y', 'i', 's', 'a', 'r', ...)
    bool b = false;
    int64_t i = 0;
    uint64_t u = 0;
    double d = 0;
    std::string s;
    std::vector<Value> items;

    bool boolean() const { return kind == Kind::Bool && b; }
    int64_t integer() const;
    uint64_t unsigned_integer() const;
    double number() const;
};

using Props = std::map<std::string, Value>;                // property name -> value
using Interfaces = std::map<std::string, Props>;           // interface -> properties
using Objects = std::map<std::string, Interfaces>;         // object path -> interfaces

// Reads the next complete value of `m` (throws Failure on a malformed message).
Value read_value(sd_bus_message* m);
// Turns a decoded a{sv} into a map.
Props to_props(const Value& dict);
// The property `name` of `props`, a None value when there is none.
// A `const char*` name, not a std::string: GCC 14 takes a temporary string argument for one the
// returned reference may point into (-Wdangling-reference).
const Value& property(const Props& props, const char* name);

class Client {
public:
    using Appender = std::function<int(sd_bus_message*)>;

    explicit Client(caracara::dbus::BusChoice choice) : choice_(std::move(choice)) {}

    // Connects on first use.
    sd_bus* bus();
    const caracara::dbus::BusChoice& choice() const { return choice_; }

    // A method call to `member` on org.caracara.Vehicle1 with its arguments appended, never
    // auto-starting the daemon; throws Failure when it cannot be built.
    caracara::dbus::MessagePtr new_call(const char* path, const char* iface, const char* member,
                                        const Appender& append = {});

    // Calls `member` on org.caracara.Vehicle1 (never auto-starting it) and returns the reply;
    // throws Failure with the exit code the error deserves. timeout_usec 0 = sd-bus default.
    caracara::dbus::MessagePtr call(const char* path, const char* iface, const char* member,
                                    const Appender& append = {}, uint64_t timeout_usec = 0);

    // Properties.Get of one property.
    Value get_property(const char* path, const char* iface, const char* name);

    // Properties.GetAll on one object.
    Props get_all(const char* path, const char* iface);
    // Every object with its properties: ObjectManager.GetManagedObjects on the root (plus the
    // root's own properties if the manager does not list itself).
    Objects get_objects();

    // The Failure for a failed call or lost connection (shared with the monitor).
    Failure failure_for(const sd_bus_error& error, int r, uint64_t timeout_usec);
    // The Failure for a connection that dropped: over SSH, refused (4) or lost (3) as ssh said.
    Failure lost_connection(const std::string& detail);

private:
    caracara::dbus::BusChoice choice_;
    SshStderr ssh_stderr_; // -H: ssh's stderr (declared before bus_: ssh ends before the copy stops)
    caracara::dbus::BusPtr bus_;
};

// Appender for plain sd_bus_message_append arguments, e.g. append_args("yyy", r, g, b).
template <typename... A>
Client::Appender append_args(const char* signature, A... args) {
    return [=](sd_bus_message* m) { return sd_bus_message_append(m, signature, args...); };
}

} // namespace caracara::client
