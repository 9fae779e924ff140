// Serves the device protocol (drivers/protocol/sim_protocol.hpp) on a Unix SOCK_SEQPACKET socket:
// the simulator's stand-in for the kernel's i2c-dev and spidev. The socket, its clients and
// the reply timing live here; what each request does is DeviceOps'.
#pragma once

#include "drivers/protocol/sim_protocol.hpp"
#include "drivers/sdbus/sdbus.hpp"
#include "sim/device_ops.hpp"
#include "sim/device_session.hpp"
#include "sim/sim_vehicle.hpp"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace caracara::sim {

class DeviceServer {
public:
    DeviceServer(sd_event* event, SimVehicle& vehicle);
    ~DeviceServer();
    int listen(const std::string& path); // -errno
    uint64_t bad_requests() const { return ops_.bad_requests(); }
    size_t clients() const { return clients_.size(); }

private:
    struct Client {
        DeviceServer* server = nullptr;
        int fd = -1;
        dbus::SourcePtr io;
        dbus::SourcePtr reply_timer;
        uint64_t due_ns = 0; // when the held reply is due
        DeviceSession session;
        // One reply buffer per client, reused for every request (the hot path of the seam).
        std::array<uint8_t, simproto::kMaxMessage> reply{};
        size_t reply_len = 0;
    };

    static int on_accept(sd_event_source*, int fd, uint32_t, void* userdata);
    static int on_client(sd_event_source*, int fd, uint32_t revents, void* userdata);
    static int on_reply_due(sd_event_source*, uint64_t, void* userdata);
    void drop(Client* c);
    void send_reply(Client& c);
    void push_gpio_event(int line, int value, uint64_t when_ns);

    sd_event* event_;
    SimVehicle& vehicle_;
    int listen_fd_ = -1;
    std::string path_;
    dbus::SourcePtr accept_source_;
    DeviceOps ops_;
    std::map<Client*, std::unique_ptr<Client>> clients_;
};

} // namespace caracara::sim
