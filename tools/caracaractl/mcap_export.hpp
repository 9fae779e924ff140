// caracaractl export --format mcap: a recorded dive as MCAP on the live bridge's channels (JSON,
// for Foxglove), or with --encoding cdr on caracara-ros's topics for rosbag2, named from
// caracara-ros's settings as it names them live (docs/ros2.md).
#pragma once

#include "core/dive_format.hpp"
#include "tools/ros/ros_conventions.hpp"

#include <optional>
#include <string>

namespace caracara::ctl {

struct McapExport {
    std::string out;                                  // --out; "" = stdout when it is no terminal
    bool cdr = false;                                 // --encoding cdr
    std::optional<caracara::ros::RangeLayout> distro; // --distro: Range's layout, ROS_DISTRO (default humble)
    std::optional<std::string> ros_config;            // --ros-config; else caracara-ros's default file if there
};

// Writes it; returns the exit status. Throws Failure: usage (binary to a terminal), a bad settings
// file (named by load_config, nothing written), a file that cannot be written.
int export_mcap(const caracara::dive::Dive& d, const McapExport& e);

} // namespace caracara::ctl
