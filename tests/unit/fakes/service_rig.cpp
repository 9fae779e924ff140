#include "tests/unit/fakes/service_rig.hpp"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>

namespace caracara::test {

ServiceRig::ServiceRig(const std::string& control, const std::string& sections, bool kill_switch_set)
    : rig_(control, sections, kill_switch_set) {
    char tmpl[] = "/tmp/caracara-unit-XXXXXX";
    if (!mkdtemp(tmpl))
        throw std::runtime_error("mkdtemp failed");
    dir_ = tmpl;
    start_private_bus(dbus_daemon_, dir_, "bus");
    server_ = connect("caracarad");
    // As daemon/main.cpp composes it.
    VehicleDaemon& d = rig_.daemon();
    service_ = std::make_unique<dbus::VehicleService>(
        server_.get(), dbus::VehicleService::Parts{{d.vehicle(), d.packets(), d.teensy(), d.loop(), d.config().control,
                                                    d.failsafes(), d.motor_test(), d.directions(), d.preflight(),
                                                    d.bus_scan()},
                                                   d.bus(), d.bus().monitor(), d.teensy(), d.events()});
    d.events().attach(service_.get());
    if (int r = service_->start(); r < 0)
        throw std::runtime_error("cannot publish the service: " + std::string(strerror(-r)));
    probe_ = std::make_unique<dbus::BusInputProbe>(server_.get());
    d.loop().set_input_probe(probe_.get());
    client_ = connect("caracara-test");
}

ServiceRig::~ServiceRig() {
    rig_.loop().set_input_probe(nullptr);
    rig_.daemon().events().attach(nullptr);
    service_.reset();
    watches_.clear();
    client_.reset();
    server_.reset();
    dbus_daemon_.stop();
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
}

dbus::BusPtr ServiceRig::connect(const char* description) {
    dbus::BusPtr bus;
    const dbus::BusChoice choice{dbus::BusChoice::Kind::Address, "unix:path=" + dir_ + "/bus"};
    if (int r = dbus::open_bus(choice, description, bus); r < 0)
        throw std::runtime_error("cannot connect to the private bus: " + std::string(strerror(-r)));
    if (int r = sd_bus_attach_event(bus.get(), rig_.event(), SD_EVENT_PRIORITY_NORMAL); r < 0)
        throw std::runtime_error("cannot attach the bus to the loop");
    return bus;
}

std::string ServiceRig::client_name() {
    const char* name = nullptr;
    if (sd_bus_get_unique_name(client_.get(), &name) < 0)
        throw std::runtime_error("no unique name");
    return name;
}

namespace {
int on_reply(sd_bus_message* m, void* userdata, sd_bus_error*) {
    auto* out = static_cast<std::optional<BusReply>*>(userdata);
    BusReply r;
    if (const sd_bus_error* e = sd_bus_message_get_error(m)) {
        r.error = e->name ? e->name : "";
        r.message = e->message ? e->message : "";
    }
    r.reply.reset(sd_bus_message_ref(m));
    *out = std::move(r);
    return 0;
}
} // namespace

BusReply ServiceRig::call_with(const char* path, const char* iface, const char* method,
                               const std::function<int(sd_bus_message*)>& append, sd_bus* bus,
                               const char* destination) {
    sd_bus* b = bus ? bus : client_.get();
    sd_bus_message* m = nullptr;
    if (sd_bus_message_new_method_call(b, &m, destination, path, iface, method) < 0)
        throw std::runtime_error(std::string("cannot build ") + method);
    dbus::MessagePtr call(m);
    if (append && append(m) < 0)
        throw std::runtime_error(std::string("cannot append the arguments of ") + method);
    std::optional<BusReply> reply;
    sd_bus_slot* slot = nullptr;
    if (sd_bus_call_async(b, &slot, m, on_reply, &reply, 0) < 0)
        throw std::runtime_error(std::string("cannot call ") + method);
    dbus::SlotPtr held(slot);
    // A give-up time, not a bound: the reply comes in a few loop turns, or the window of the
    // method that answers later (Preflight, ScanBus).
    if (!rig_.run_until([&] { return reply.has_value(); }, 20000))
        throw std::runtime_error(std::string("no reply to ") + method);
    return std::move(*reply);
}

BusReply ServiceRig::get(const char* path, const char* iface, const char* property, const char* type) {
    BusReply r = call(path, "org.freedesktop.DBus.Properties",
                      "Get", "ss", iface, property);
    if (!r.ok())
        throw std::runtime_error(std::string("cannot get ") + property + ": " + r.error);
    if (sd_bus_message_enter_container(r.reply.get(), 'v', type) < 0)
        throw std::runtime_error(std::string(property) + " is not of type " + type);
    return r;
}

std::string ServiceRig::text(const char* path, const char* iface, const char* property) {
    BusReply r = get(path, iface, property, "s");
    const char* s = nullptr;
    if (sd_bus_message_read(r.reply.get(), "s", &s) < 0)
        throw std::runtime_error(std::string("cannot read ") + property);
    return s;
}

std::vector<int32_t> ServiceRig::ints(const char* path, const char* iface, const char* property) {
    BusReply r = get(path, iface, property, "ai");
    const void* p = nullptr;
    size_t n = 0;
    if (sd_bus_message_read_array(r.reply.get(), 'i', &p, &n) < 0)
        throw std::runtime_error(std::string("cannot read ") + property);
    const auto* v = static_cast<const int32_t*>(p);
    return {v, v + n / sizeof(int32_t)};
}

BusReply ServiceRig::set_thrust(const std::vector<int32_t>& values, sd_bus* bus) {
    return call_with(dbus::kRootPath, dbus::kVehicleIface, "SetThrust", [&](sd_bus_message* m) {
        return sd_bus_message_append_array(m, 'i', values.data(), values.size() * sizeof(int32_t));
    }, bus);
}

bool ServiceRig::each_ordered(const std::vector<int32_t>& values, long from) {
    const auto ev = rig_.wire().events();
    for (std::size_t i = 0; i < values.size(); ++i)
        if (find(ev, [&](const WireEvent& e) { return e.is_order(i, on_wire(values[i])); }, from) < 0)
            return false;
    return true;
}

void ServiceRig::watch_property(const char* path, const char* property, const char* type,
                                std::function<void(sd_bus_message*)> read) {
    auto watch = std::make_unique<PropertyWatch>(PropertyWatch{property, type, std::move(read), nullptr});
    auto on_changed = [](sd_bus_message* m, void* userdata, sd_bus_error*) {
        auto* w = static_cast<PropertyWatch*>(userdata);
        const char* iface = nullptr;
        if (sd_bus_message_read(m, "s", &iface) < 0 || sd_bus_message_enter_container(m, 'a', "{sv}") < 0)
            return 0;
        while (sd_bus_message_enter_container(m, 'e', "sv") > 0) {
            const char* name = nullptr;
            sd_bus_message_read(m, "s", &name);
            if (w->property == name && sd_bus_message_enter_container(m, 'v', w->type.c_str()) > 0) {
                w->read(m);
                sd_bus_message_exit_container(m);
            } else {
                sd_bus_message_skip(m, "v");
            }
            sd_bus_message_exit_container(m);
        }
        return 0;
    };
    sd_bus_slot* slot = nullptr;
    if (sd_bus_match_signal(client(), &slot, dbus::kBusName, path, "org.freedesktop.DBus.Properties",
                            "PropertiesChanged", on_changed, watch.get()) < 0)
        throw std::runtime_error(std::string("cannot watch ") + property);
    watch->slot.reset(slot);
    watches_.push_back(std::move(watch));
}

} // namespace caracara::test
