#include "tools/caracaractl/mcap_export.hpp"

#include "tools/client/client.hpp"
#include "tools/foxglove/dive_mcap.hpp"
#include "tools/foxglove/dive_ros_mcap.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <unistd.h>

namespace caracara::ctl {

using caracara::client::Failure;

int export_mcap(const caracara::dive::Dive& d, const McapExport& e) {
    if (e.out.empty() && ::isatty(STDOUT_FILENO))
        throw Failure{client::kExitUsage, "MCAP is binary: give --out FILE or redirect the output"};
    // caracara-ros's settings, read as it reads them: --ros-config, else its default file if there.
    caracara::ros::RosConfig config;
    const std::string path = e.ros_config.value_or(caracara::ros::kDefaultConfigPath);
    if (e.cdr && (e.ros_config || ::access(path.c_str(), F_OK) == 0))
        if (const std::string why = caracara::ros::load_config(path, config); !why.empty())
            throw Failure{client::kExitRefused, why};
    const std::vector<uint8_t> bytes =
        e.cdr ? caracara::foxglove::dive_to_ros_mcap(d, config, e.distro.value_or(caracara::ros::RangeLayout::Humble))
              : caracara::foxglove::dive_to_mcap(d);
    std::ofstream file;
    if (!e.out.empty()) {
        file.open(e.out, std::ios::binary | std::ios::trunc);
        if (!file)
            throw Failure{client::kExitRefused, "cannot write " + e.out + ": " + std::strerror(errno)};
    }
    std::ostream& s = e.out.empty() ? std::cout : file;
    s.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    s.flush();
    if (!s)
        throw Failure{client::kExitRefused, "writing the MCAP file failed"};
    return client::kExitOk;
}

} // namespace caracara::ctl
