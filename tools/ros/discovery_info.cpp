#include "tools/ros/discovery_info.hpp"

#include "tools/ros/dds_qos.hpp"
#include "tools/ros/type_name.hpp"

#include <cstring>
#include <ros_msgs.h>
#include <stdexcept>

namespace caracara::ros {

namespace {

DiscoveryInfo::Guid guid_of(dds_entity_t e) {
    dds_guid_t g{};
    dds_get_guid(e, &g);
    DiscoveryInfo::Guid out;
    std::memcpy(out.data(), g.v, out.size());
    return out;
}

// One layout's message (Humble's or Jazzy's generated types), written once. A gid is the GUID
// and zeros after it, as rmw_cyclonedds_cpp and rmw_fastrtps_cpp make theirs.
template <typename Info, typename Node, typename Gid>
void write(dds_entity_t writer, const DiscoveryInfo::Guid& participant, const std::string& ns,
           const std::vector<DiscoveryInfo::Guid>& readers, const std::vector<DiscoveryInfo::Guid>& writers) {
    static_assert(sizeof(Gid{}.data) >= sizeof(DiscoveryInfo::Guid));
    const auto gid = [](const DiscoveryInfo::Guid& g) {
        Gid out{};
        std::memcpy(out.data, g.data(), g.size());
        return out;
    };
    const auto gids = [&](const std::vector<DiscoveryInfo::Guid>& v) {
        std::vector<Gid> out;
        for (const auto& g : v)
            out.push_back(gid(g));
        return out;
    };
    std::vector<Gid> r = gids(readers), w = gids(writers);
    Node node{};
    std::strncpy(node.node_namespace, ns.c_str(), sizeof node.node_namespace - 1);
    std::strncpy(node.node_name, DiscoveryInfo::kNodeName, sizeof node.node_name - 1);
    const auto n = [](const std::vector<Gid>& v) { return static_cast<uint32_t>(v.size()); };
    node.reader_gid_seq = {n(r), n(r), r.data(), false};
    node.writer_gid_seq = {n(w), n(w), w.data(), false};
    Info info{gid(participant), {1, 1, &node, false}};
    dds_write(writer, &info);
}

} // namespace

DiscoveryInfo::DiscoveryInfo(dds_entity_t participant, const RosConfig& config)
    : jazzy_(config.range_layout == RangeLayout::Jazzy), participant_entity_(participant),
      namespace_(config.ros_namespace.empty() ? "/" : config.ros_namespace), participant_(guid_of(participant)) {
    make_writer();
}

void DiscoveryInfo::make_writer() {
    const dds_entity_t participant = participant_entity_;
    static const dds_topic_descriptor_t kJazzy = under_type_name(jazzy_rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                                                 "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
    // The topic is not under "rt/": rmw_dds_common names it so (avoid_ros_namespace_conventions).
    const dds_entity_t topic = dds_create_topic(participant, jazzy_ ? &kJazzy : &rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                                "ros_discovery_info", nullptr, nullptr);
    if (topic < 0)
        throw std::runtime_error(std::string("DDS topic ros_discovery_info: ") + dds_strretcode(topic));
    dds_qos_t* q = qos_for(Profile::Latched);
    writer_ = dds_create_writer(participant, topic, q, nullptr);
    dds_delete_qos(q);
    if (writer_ < 0)
        throw std::runtime_error(std::string("DDS writer on ros_discovery_info: ") + dds_strretcode(writer_));
    publish();
}

void DiscoveryInfo::set_layout(RangeLayout layout) {
    if (jazzy_ == (layout == RangeLayout::Jazzy))
        return;
    // The other layout's topic beside this one (Cyclone takes both type layouts under one name);
    // the old writer goes, so no peer gets a Gid size it cannot read.
    dds_delete(writer_);
    jazzy_ = layout == RangeLayout::Jazzy;
    make_writer();
}

void DiscoveryInfo::remove_writer(dds_entity_t writer) {
    std::erase(writers_, guid_of(writer));
    publish();
}

void DiscoveryInfo::add_writer(dds_entity_t writer) {
    writers_.push_back(guid_of(writer));
    publish();
}

void DiscoveryInfo::add_reader(dds_entity_t reader) {
    readers_.push_back(guid_of(reader));
    publish();
}

void DiscoveryInfo::publish() {
    if (jazzy_)
        write<jazzy_rmw_dds_common_msg_dds__ParticipantEntitiesInfo_, jazzy_rmw_dds_common_msg_dds__NodeEntitiesInfo_,
              jazzy_rmw_dds_common_msg_dds__Gid_>(writer_, participant_, namespace_, readers_, writers_);
    else
        write<rmw_dds_common_msg_dds__ParticipantEntitiesInfo_, rmw_dds_common_msg_dds__NodeEntitiesInfo_,
              rmw_dds_common_msg_dds__Gid_>(writer_, participant_, namespace_, readers_, writers_);
}

} // namespace caracara::ros
