#include "tools/ros/distro_detector.hpp"

#include "tools/ros/dds_qos.hpp"
#include "tools/ros/type_name.hpp"

#include <cstring>
#include <dds/ddsi/ddsi_serdata.h>
#include <ros_msgs.h>
#include <set>
#include <stdexcept>
#include <vector>

namespace caracara::ros {

namespace {

constexpr std::size_t kHumbleGid = 24, kJazzyGid = 16;

// Classic CDR (XCDR1) as rmw_dds_common's types are sent: each uint32 aligned to 4 from the
// payload's start, octet arrays unaligned.
class Cursor {
public:
    Cursor(std::span<const uint8_t> payload, bool little) : p_(payload), little_(little) {}
    bool skip(std::size_t n) {
        if (n > p_.size() - pos_)
            return false;
        pos_ += n;
        return true;
    }
    bool u32(uint32_t& v) {
        pos_ = (pos_ + 3) & ~std::size_t{3};
        if (pos_ > p_.size() || p_.size() - pos_ < 4)
            return false;
        const uint8_t* b = p_.data() + pos_;
        v = little_ ? b[0] | b[1] << 8 | b[2] << 16 | static_cast<uint32_t>(b[3]) << 24
                    : b[3] | b[2] << 8 | b[1] << 16 | static_cast<uint32_t>(b[0]) << 24;
        pos_ += 4;
        return true;
    }
    std::size_t pos() const { return pos_; }

private:
    std::span<const uint8_t> p_;
    bool little_;
    std::size_t pos_ = 0;
};

// Where a ParticipantEntitiesInfo with `gid`-byte Gids ends in `payload`, none if it cannot.
std::optional<std::size_t> parsed_end(std::span<const uint8_t> payload, bool little, std::size_t gid) {
    Cursor c(payload, little);
    uint32_t nodes = 0;
    if (!c.skip(gid) || !c.u32(nodes) || nodes > payload.size())
        return std::nullopt;
    for (uint32_t i = 0; i < nodes; ++i) {
        uint32_t n = 0;
        for (int s = 0; s < 2; ++s) // namespace, name
            if (!c.u32(n) || !c.skip(n))
                return std::nullopt;
        for (int s = 0; s < 2; ++s) // reader gids, writer gids
            if (!c.u32(n) || n > payload.size() || !c.skip(std::size_t{n} * gid))
                return std::nullopt;
    }
    return c.pos();
}

} // namespace

std::optional<RangeLayout> DistroDetector::layout_of(std::span<const uint8_t> cdr) {
    if (cdr.size() < 4 || cdr[0] != 0 || cdr[1] > 1)
        return std::nullopt; // CDR_BE (0) or CDR_LE (1), XCDR1 as ROS 2 sends
    const std::span<const uint8_t> payload = cdr.subspan(4);
    // The encapsulation options' last two bits: padding added after the data (XTypes 1.3 7.6.3.1.2).
    const std::size_t pad = cdr[3] & 3u;
    const auto fits = [&](std::size_t gid) {
        const auto end = parsed_end(payload, cdr[1] == 1, gid);
        return end && (*end == payload.size() || *end + pad == payload.size());
    };
    const bool humble = fits(kHumbleGid), jazzy = fits(kJazzyGid);
    if (humble == jazzy)
        return std::nullopt;
    return humble ? RangeLayout::Humble : RangeLayout::Jazzy;
}

DistroDetector::DistroDetector(dds_entity_t participant) {
    dds_guid_t own{};
    dds_get_guid(participant, &own);
    std::memcpy(own_prefix_.data(), own.v, own_prefix_.size());
    static const dds_topic_descriptor_t kJazzy = under_type_name(jazzy_rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc,
                                                                 "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_");
    // As a ROS 2 graph cache reads it: reliable, transient-local (a peer's current one at once);
    // every peer's kept, not the last of all (the topic has no key).
    dds_qos_t* q = qos_for(Profile::Latched);
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    const dds_entity_t topic = dds_create_topic(participant, &kJazzy, "ros_discovery_info", nullptr, nullptr);
    reader_ = topic < 0 ? topic : dds_create_reader(participant, topic, q, nullptr);
    dds_delete_qos(q);
    if (reader_ < 0)
        throw std::runtime_error(std::string("DDS reader on ros_discovery_info: ") + dds_strretcode(reader_));
}

DistroDetector::~DistroDetector() {
    if (reader_ > 0)
        dds_delete(reader_);
}

bool DistroDetector::update() {
    const auto before = std::pair{peers(RangeLayout::Humble), peers(RangeLayout::Jazzy)};
    std::set<dds_instance_handle_t> matched;
    {
        const dds_entity_t r = reader_;
        constexpr int kBatch = 16;
        for (dds_return_t n = kBatch; n == kBatch;) {
            ddsi_serdata* sd[kBatch];
            dds_sample_info_t info[kBatch];
            n = dds_takecdr(r, sd, kBatch, info, DDS_ANY_STATE);
            for (dds_return_t i = 0; i < n; ++i) {
                if (info[i].valid_data) {
                    std::vector<uint8_t> cdr(ddsi_serdata_size(sd[i]));
                    ddsi_serdata_to_ser(sd[i], 0, cdr.size(), cdr.data());
                    // The participant's gid begins with its GUID: caracara-ros's own is no peer.
                    const bool own = cdr.size() >= 4 + own_prefix_.size() &&
                                     std::memcmp(cdr.data() + 4, own_prefix_.data(), own_prefix_.size()) == 0;
                    if (const auto layout = layout_of(cdr); layout && !own)
                        peers_[info[i].publication_handle] = *layout;
                }
                ddsi_serdata_unref(sd[i]);
            }
        }
        dds_instance_handle_t h[64];
        const dds_return_t m = dds_get_matched_publications(r, h, 64);
        for (dds_return_t i = 0; i < m && i < 64; ++i)
            matched.insert(h[i]);
    }
    std::erase_if(peers_, [&](const auto& p) { return !matched.contains(p.first); });
    return before != std::pair{peers(RangeLayout::Humble), peers(RangeLayout::Jazzy)};
}

unsigned DistroDetector::peers(RangeLayout distro) const {
    unsigned n = 0;
    for (const auto& [handle, layout] : peers_)
        n += layout == distro;
    return n;
}

bool DistroDetector::choose(SpokenDistro& distro) const {
    const unsigned humble = peers(RangeLayout::Humble), jazzy = peers(RangeLayout::Jazzy);
    if (!humble && !jazzy)
        return false;
    const auto count = [](unsigned n) { return std::to_string(n) + (n == 1 ? " participant" : " participants"); };
    if (!humble || !jazzy) {
        distro.layout = humble ? RangeLayout::Humble : RangeLayout::Jazzy;
        distro.why = "the peers' ros_discovery_info: " + count(humble + jazzy) + ", all " +
                     std::string(name_of(distro.layout));
    } else {
        // Both: the distro of more peers (on a tie, the one spoken already: no flapping). The
        // others cannot read Range nor list this node: a setting to make (range_layout).
        if (humble != jazzy)
            distro.layout = humble > jazzy ? RangeLayout::Humble : RangeLayout::Jazzy;
        distro.why = "peers of both distros (humble " + count(humble) + ", jazzy " + count(jazzy) + "): " +
                     std::string(name_of(distro.layout)) + (humble != jazzy ? ", the more" : ", spoken already") +
                     "; the others cannot read Range or list this node (set range_layout to choose)";
    }
    return true;
}

} // namespace caracara::ros
