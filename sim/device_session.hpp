// What one client of the device socket has open: its device handles and GPIO lines, as a
// process's file descriptors are to the kernel.
#pragma once

#include "sim/sim_vehicle.hpp"

#include <map>
#include <string>

namespace caracara::sim {

struct DeviceSession {
    struct Handle {
        SimVehicle::NodeKind kind;
        std::string path;
        uint32_t epoch = 0; // the node's epoch at open: an older one vanished under it
    };
    std::map<int, Handle> handles;
    std::map<int, int> gpio_lines; // handle -> line index in the GPIO model
    std::map<int, uint32_t> gpio_epochs; // handle -> the line's epoch at request (GpioModel::epoch)
    int watched_line = -1;         // a GpioWatch connection: pushes edges of this line
    int next_handle = 3;
};

} // namespace caracara::sim
