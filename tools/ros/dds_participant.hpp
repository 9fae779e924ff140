// caracara-ros's one DDS participant (Cyclone DDS) as a ROS 2 node's participant looks: on
// ROS_DOMAIN_ID's domain, "enclave=/;" in its USER_DATA (rmw_cyclonedds registers only such
// participants), every writer and reader XCDR1 on "rt/<topic>" with ROS 2's QoS profiles, each
// listed in its ros_discovery_info as the node caracara_ros's (`ros2 node list`).
#pragma once

#include "tools/ros/audit_watch.hpp"
#include "tools/ros/dds_qos.hpp"
#include "tools/ros/discovery_info.hpp"
#include "tools/ros/ros_config.hpp"

#include <dds/dds.h>
#include <memory>
#include <string>

namespace caracara::ros {

class DdsParticipant {
public:
    // Throws std::runtime_error with Cyclone's message when the domain cannot be made.
    explicit DdsParticipant(const RosConfig& config);
    ~DdsParticipant();
    DdsParticipant(const DdsParticipant&) = delete;
    DdsParticipant& operator=(const DdsParticipant&) = delete;

    dds_entity_t handle() const { return participant_; }
    // With DDS Security: throws std::runtime_error unless only writers whose permissions allow
    // it reach the reader on ROS topic `ros_name` (audit_watch.hpp). Without: nothing.
    void require_protected(const std::string& ros_name) const;
    // With DDS Security: logs the peers it refuses, from now on, on `event`.
    void watch(sd_event* event);
    // A writer of `desc` on ROS topic `ros_name` ("/caracara/imu" -> "rt/caracara/imu").
    dds_entity_t writer(const dds_topic_descriptor_t* desc, const std::string& ros_name, Profile profile);
    dds_entity_t reader(const dds_topic_descriptor_t* desc, const std::string& ros_name, Profile profile,
                        const dds_listener_t* listener);
    // Deletes a writer made here, and takes it off the node's list.
    void delete_writer(dds_entity_t writer);
    DiscoveryInfo& discovery_info() { return *discovery_info_; }

private:
    dds_entity_t topic(const dds_topic_descriptor_t* desc, const std::string& ros_name);

    std::unique_ptr<AuditWatch> audit_; // with DDS Security; before the participant, after it goes
    dds_entity_t domain_ = 0;
    dds_entity_t participant_ = 0;
    std::unique_ptr<DiscoveryInfo> discovery_info_; // lists every reader and writer made here
};

} // namespace caracara::ros
