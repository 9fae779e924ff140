// rmw_dds_common's ParticipantEntitiesInfo on "ros_discovery_info": the participant's gid and
// its one node (namespace, name, the gids of its readers and writers), which ROS 2's graph
// cache reads to list nodes (`ros2 node list`, `ros2 node info`). Written again whenever a
// reader or writer is added; reliable, transient-local, keep-last 1 as rmw_cyclonedds_cpp's own
// (a late ROS 2 tool gets the current one). The Gid is Humble's 24 bytes or Jazzy's 16, picked
// by the distro spoken (SpokenDistro: the config's range_layout, else the peers').
#pragma once

#include "tools/ros/ros_config.hpp"

#include <array>
#include <dds/dds.h>
#include <string>
#include <vector>

namespace caracara::ros {

class DiscoveryInfo {
public:
    using Guid = std::array<uint8_t, 16>; // a DDS GUID: prefix (12 bytes), entity id (4)
    // The node's name as `ros2 node list` shows it under the config's namespace.
    static constexpr const char* kNodeName = "caracara_ros";

    // Throws std::runtime_error with Cyclone's message when the writer cannot be made.
    DiscoveryInfo(dds_entity_t participant, const RosConfig& config);
    DiscoveryInfo(const DiscoveryInfo&) = delete;
    DiscoveryInfo& operator=(const DiscoveryInfo&) = delete;

    void add_writer(dds_entity_t writer);
    void add_reader(dds_entity_t reader);
    void remove_writer(dds_entity_t writer);
    // Written from now on in `layout`'s Gid size (the distro caracara-ros speaks changed).
    void set_layout(RangeLayout layout);

private:
    void publish();
    void make_writer();

    dds_entity_t writer_ = 0;
    bool jazzy_;
    dds_entity_t participant_entity_;
    std::string namespace_;
    Guid participant_{};
    std::vector<Guid> writers_, readers_;
};

} // namespace caracara::ros
