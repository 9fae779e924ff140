// The daemon's D-Bus objects (dbus/VehicleService) as caracarad composes them, serving a
// DaemonRig (the VehicleDaemon on the fakes of the device seam) on a private dbus-daemon, and a
// client connection on the same sd-event loop: a test calls and reads as a D-Bus client does,
// and judges by what the client gets back and by the fake wire.
#pragma once

#include "dbus/bus_input_probe.hpp"
#include "dbus/vehicle_service.hpp"
#include "tests/integration/sim_fixture.hpp"
#include "tests/unit/fakes/daemon_rig.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace caracara::test {

// Eight motor values, each thruster's its own (a mixed-up thruster shows), and eight zeros.
inline const std::vector<int32_t> kThrust{1000, -2000, 3000, -4000, 500, -500, 1500, -1500};
inline const std::vector<int32_t> kZeros(kMotorCount, 0);

// A method's reply as the client got it: the error's name and text, or the return message.
struct BusReply {
    std::string error; // "" on success
    std::string message;
    dbus::MessagePtr reply;
    bool ok() const { return error.empty(); }
};

class ServiceRig {
public:
    // The DaemonRig's arguments.
    explicit ServiceRig(const std::string& control = "loop_rate_hz = 50\n", const std::string& sections = "",
                        bool kill_switch_set = false);
    ~ServiceRig();
    ServiceRig(const ServiceRig&) = delete;
    ServiceRig& operator=(const ServiceRig&) = delete;

    DaemonRig& rig() { return rig_; }
    dbus::VehicleService& service() { return *service_; }
    sd_bus* client() { return client_.get(); }
    // The client's unique name: who the daemon sees calling.
    std::string client_name();
    // Another client on the same bus and loop (e.g. one that leaves).
    dbus::BusPtr connect(const char* description);

    // Calls `method` of `destination` through `bus` (the client when null), the arguments
    // appended by `append`, and runs the loop until the reply.
    BusReply call_with(const char* path, const char* iface, const char* method,
                       const std::function<int(sd_bus_message*)>& append, sd_bus* bus = nullptr,
                       const char* destination = dbus::kBusName);
    template <typename... A>
    BusReply call(const char* path, const char* iface, const char* method, const char* signature, A... args) {
        return call_with(path, iface, method,
                         [&](sd_bus_message* m) { return sd_bus_message_append(m, signature, args...); });
    }
    // Properties.Get: the reply, read on into the variant of `type`.
    BusReply get(const char* path, const char* iface, const char* property, const char* type);
    std::string text(const char* path, const char* iface, const char* property);
    template <typename T>
    T basic(const char* path, const char* iface, const char* property, char type) {
        const char t[2] = {type, 0};
        BusReply r = get(path, iface, property, t);
        T v{};
        if (sd_bus_message_read_basic(r.reply.get(), type, &v) < 0)
            throw std::runtime_error(std::string("cannot read ") + property);
        return v;
    }
    std::vector<int32_t> ints(const char* path, const char* iface, const char* property);

    // SetThrust(values) on the vehicle through `bus` (the client when null).
    BusReply set_thrust(const std::vector<int32_t>& values, sd_bus* bus = nullptr);
    // Each thruster was ordered its value of `values` on the fake wire (from event `from` on).
    bool each_ordered(const std::vector<int32_t>& values, long from = 0);

    // Watches PropertiesChanged on `path` for the rig's life: `read` gets each announced value of
    // `property`, the message inside its variant (of `type`), and reads it all.
    void watch_property(const char* path, const char* property, const char* type,
                        std::function<void(sd_bus_message*)> read);

private:
    struct PropertyWatch {
        std::string property;
        std::string type;
        std::function<void(sd_bus_message*)> read;
        dbus::SlotPtr slot;
    };

    DaemonRig rig_;
    std::string dir_;
    Process dbus_daemon_;
    dbus::BusPtr server_;
    dbus::BusPtr client_;
    std::unique_ptr<dbus::VehicleService> service_;
    std::unique_ptr<dbus::BusInputProbe> probe_;
    std::vector<std::unique_ptr<PropertyWatch>> watches_;
};

} // namespace caracara::test
