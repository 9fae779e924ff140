#include "tools/client/client.hpp"

#include <cerrno>
#include <csignal>
#include <cstring>

namespace caracara::client {

namespace {

// sd-bus's default method call timeout, for messages (sd_bus_call with timeout 0).
constexpr uint64_t kDefaultTimeoutUsec = 25'000'000;

struct ErrorGuard {
    sd_bus_error e = SD_BUS_ERROR_NULL;
    ~ErrorGuard() { sd_bus_error_free(&e); }
};

std::string errno_text(int r) { return std::strerror(r < 0 ? -r : r); }

void check(int r, const char* what) {
    if (r < 0)
        throw Failure{kExitRefused, std::string("malformed message from caracarad (") + what + "): " + errno_text(r)};
}

template <typename T>
T read_basic(sd_bus_message* m, char type) {
    T v{};
    check(sd_bus_message_read_basic(m, type, &v), "value");
    return v;
}

bool is_one_of(const char* name, std::initializer_list<const char*> names) {
    for (const char* n : names)
        if (name && std::strcmp(name, n) == 0)
            return true;
    return false;
}

// The last non-empty line of what ssh said, for caracaractl's own message.
std::string last_line(const std::string& text) {
    const size_t end = text.find_last_not_of("\r\n");
    if (end == std::string::npos)
        return {};
    const size_t start = text.find_last_of('\n', end);
    return text.substr(start == std::string::npos ? 0 : start + 1, end - (start == std::string::npos ? 0 : start + 1) + 1);
}

} // namespace

bool stop_signal_pending() {
    sigset_t pending;
    return sigpending(&pending) == 0 && (sigismember(&pending, SIGINT) == 1 || sigismember(&pending, SIGTERM) == 1);
}

int64_t Value::integer() const {
    switch (kind) {
    case Kind::Bool: return b ? 1 : 0;
    case Kind::Signed: return i;
    case Kind::Unsigned: return static_cast<int64_t>(u);
    case Kind::Double: return static_cast<int64_t>(d);
    default: return 0;
    }
}

uint64_t Value::unsigned_integer() const {
    return kind == Kind::Unsigned ? u : static_cast<uint64_t>(integer());
}

double Value::number() const {
    switch (kind) {
    case Kind::Double: return d;
    case Kind::Signed: return static_cast<double>(i);
    case Kind::Unsigned: return static_cast<double>(u);
    default: return 0;
    }
}

Value read_value(sd_bus_message* m) {
    char type = 0;
    const char* contents = nullptr;
    check(sd_bus_message_peek_type(m, &type, &contents), "type");
    Value v;
    v.code = type;
    switch (type) {
    case SD_BUS_TYPE_BOOLEAN:
        v.kind = Value::Kind::Bool;
        v.b = read_basic<int>(m, type) != 0;
        break;
    case SD_BUS_TYPE_BYTE: v.kind = Value::Kind::Unsigned; v.u = read_basic<uint8_t>(m, type); break;
    case SD_BUS_TYPE_UINT16: v.kind = Value::Kind::Unsigned; v.u = read_basic<uint16_t>(m, type); break;
    case SD_BUS_TYPE_UINT32: v.kind = Value::Kind::Unsigned; v.u = read_basic<uint32_t>(m, type); break;
    case SD_BUS_TYPE_UINT64: v.kind = Value::Kind::Unsigned; v.u = read_basic<uint64_t>(m, type); break;
    case SD_BUS_TYPE_INT16: v.kind = Value::Kind::Signed; v.i = read_basic<int16_t>(m, type); break;
    case SD_BUS_TYPE_INT32: v.kind = Value::Kind::Signed; v.i = read_basic<int32_t>(m, type); break;
    case SD_BUS_TYPE_INT64: v.kind = Value::Kind::Signed; v.i = read_basic<int64_t>(m, type); break;
    case SD_BUS_TYPE_UNIX_FD: v.kind = Value::Kind::Signed; v.i = read_basic<int>(m, type); break;
    case SD_BUS_TYPE_DOUBLE: v.kind = Value::Kind::Double; v.d = read_basic<double>(m, type); break;
    case SD_BUS_TYPE_STRING:
    case SD_BUS_TYPE_OBJECT_PATH:
    case SD_BUS_TYPE_SIGNATURE:
        v.kind = Value::Kind::String;
        v.s = read_basic<const char*>(m, type);
        break;
    case SD_BUS_TYPE_VARIANT: {
        check(sd_bus_message_enter_container(m, type, contents), "variant");
        v = read_value(m);
        check(sd_bus_message_exit_container(m), "variant");
        break;
    }
    case SD_BUS_TYPE_ARRAY:
    case SD_BUS_TYPE_STRUCT:
    case SD_BUS_TYPE_DICT_ENTRY: {
        v.kind = type == SD_BUS_TYPE_ARRAY ? Value::Kind::Array : Value::Kind::Struct;
        check(sd_bus_message_enter_container(m, type, contents), "container");
        int r;
        while ((r = sd_bus_message_at_end(m, false)) == 0)
            v.items.push_back(read_value(m));
        check(r, "container");
        check(sd_bus_message_exit_container(m), "container");
        break;
    }
    default:
        throw Failure{kExitRefused, std::string("malformed message from caracarad: unexpected type '") + type + "'"};
    }
    return v;
}

Props to_props(const Value& dict) {
    Props props;
    for (const Value& entry : dict.items)
        if (entry.items.size() == 2)
            props[entry.items[0].s] = entry.items[1];
    return props;
}

const Value& property(const Props& props, const char* name) {
    static const Value none;
    const auto it = props.find(name);
    return it == props.end() ? none : it->second;
}

sd_bus* Client::bus() {
    if (!bus_) {
        const bool remote = choice_.kind == caracara::dbus::BusChoice::Kind::Remote;
        if (remote)
            ssh_stderr_.capture(); // if it cannot, ssh writes to our stderr and failures count as 3
        const int r = caracara::dbus::open_bus(choice_, "caracaractl", bus_);
        if (remote)
            ssh_stderr_.restore();
        if (r == -EINVAL && remote)
            throw Failure{kExitUsage, "-H needs [USER@]HOST[:PORT], not '" + choice_.address + "'"};
        if (r < 0 && remote) // ssh ended before the bus was up (refused, unreachable): it said why
            throw lost_connection(errno_text(r));
        if (r < 0)
            throw Failure{r == -EACCES || r == -EPERM ? kExitDenied : kExitUnavailable,
                          "cannot connect to " + choice_.describe() + ": " + errno_text(r)};
    }
    return bus_.get();
}

Failure Client::lost_connection(const std::string& detail) {
    if (choice_.kind != caracara::dbus::BusChoice::Kind::Remote)
        return {kExitUnavailable, "lost the connection to " + choice_.describe() + ": " + detail};
    // ssh has printed why (copied to our stderr already) and is exiting: wait for its last word.
    const std::string said = ssh_stderr_.said(std::chrono::seconds(2));
    const std::string why = last_line(said);
    if (SshStderr::refused(said))
        return {kExitDenied, "SSH refused the login to " + choice_.address + (why.empty() ? "" : ": " + why)};
    return {kExitUnavailable, "the SSH link to " + choice_.address + " ended: " + (why.empty() ? detail : why)};
}

Failure Client::failure_for(const sd_bus_error& error, int r, uint64_t timeout_usec) {
    const char* name = error.name;
    const std::string message = error.message ? error.message : errno_text(r);
    if (is_one_of(name, {SD_BUS_ERROR_SERVICE_UNKNOWN, SD_BUS_ERROR_NAME_HAS_NO_OWNER}))
        return {kExitUnavailable, "caracarad is not running on " + choice_.describe() + " (" + kService +
                                      " has no owner)"};
    if (is_one_of(name, {SD_BUS_ERROR_ACCESS_DENIED}) || (!name && (r == -EACCES || r == -EPERM)))
        return {kExitDenied, "permission denied: commanding caracarad needs root or membership in the "
                             "caracara group (" + message + ")"};
    // Checked before the timeout: sd-bus answers the calls pending on a closed connection with
    // NoReply ("Connection terminated").
    if (bus_ && !sd_bus_is_open(bus_.get()))
        return lost_connection(message);
    if (is_one_of(name, {SD_BUS_ERROR_NO_REPLY, SD_BUS_ERROR_TIMEOUT}) || r == -ETIMEDOUT) {
        const uint64_t t = timeout_usec ? timeout_usec : kDefaultTimeoutUsec;
        return {kExitUnavailable, "caracarad did not answer within " + std::to_string(t / 1'000'000) +
                                      " s (the request may still take effect)"};
    }
    return {kExitRefused, std::string(name ? name : "error") + ": " + message};
}

caracara::dbus::MessagePtr Client::new_call(const char* path, const char* iface, const char* member,
                                            const Appender& append) {
    sd_bus_message* raw = nullptr;
    int r = sd_bus_message_new_method_call(bus(), &raw, kService, path, iface, member);
    caracara::dbus::MessagePtr request(raw);
    // A query or command must not start the daemon behind the operator's back.
    if (r >= 0)
        r = sd_bus_message_set_auto_start(raw, false);
    if (r >= 0 && append)
        r = append(raw);
    if (r < 0)
        throw Failure{kExitUsage, std::string("cannot build the ") + member + " call: " + errno_text(r)};
    return request;
}

caracara::dbus::MessagePtr Client::call(const char* path, const char* iface, const char* member,
                                        const Appender& append, uint64_t timeout_usec) {
    caracara::dbus::MessagePtr request = new_call(path, iface, member, append);
    ErrorGuard error;
    sd_bus_message* reply = nullptr;
    const int r = sd_bus_call(bus(), request.get(), timeout_usec, &error.e, &reply);
    caracara::dbus::MessagePtr result(reply);
    if (r < 0)
        throw failure_for(error.e, r, timeout_usec);
    return result;
}

Value Client::get_property(const char* path, const char* iface, const char* name) {
    auto reply = call(path, "org.freedesktop.DBus.Properties", "Get", append_args("ss", iface, name));
    return read_value(reply.get());
}

Props Client::get_all(const char* path, const char* iface) {
    auto reply = call(path, "org.freedesktop.DBus.Properties", "GetAll", append_args("s", iface));
    return to_props(read_value(reply.get()));
}

Objects Client::get_objects() {
    auto reply = call(kRootPath, "org.freedesktop.DBus.ObjectManager", "GetManagedObjects");
    Objects objects;
    for (const Value& object : read_value(reply.get()).items) {
        if (object.items.size() != 2)
            continue;
        Interfaces& ifaces = objects[object.items[0].s];
        for (const Value& iface : object.items[1].items)
            if (iface.items.size() == 2)
                ifaces[iface.items[0].s] = to_props(iface.items[1]);
    }
    Interfaces& root = objects[kRootPath];
    if (!root.contains(kVehicleIface))
        root[kVehicleIface] = get_all(kRootPath, kVehicleIface);
    return objects;
}

} // namespace caracara::client
