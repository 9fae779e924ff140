#include "tools/ros/range_subscribers.hpp"

#include "tools/ros/gid_text.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace caracara::ros {

namespace {

// sensor_msgs/msg/Range's RIHS01 type hashes: SHA-256 of the type description (the fields, and
// those of std_msgs/Header and builtin_interfaces/Time) as rosidl_generator_type_description
// writes it. With variance (Jazzy's; Kilted's generated code carries the same), and without it
// (Humble's fields, as Iron hashes them). tests/ros/type_hash.mjs computes both from the published
// definitions.
constexpr std::string_view kRangeWithVariance = "RIHS01_b42b62562e93cbfe9d42b82fe5994dfa3d63d7d5c90a317981703f7388adff3a";
constexpr std::string_view kRangeWithoutVariance = "RIHS01_9430b1915b94d4268ff903679e8ecd09b6a67d331bd028738ec1eeb592891ebd";
constexpr const char* kRangeTypeName = "sensor_msgs::msg::dds_::Range_";

std::string plural(unsigned n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); }

} // namespace

RangeSubscribers::Asked RangeSubscribers::asked(std::string_view user_data) {
    // rmw_dds_common's USER_DATA: "key=value;" items.
    std::optional<std::string_view> hash;
    for (std::size_t at = 0; at < user_data.size();) {
        const std::size_t end = std::min(user_data.find(';', at), user_data.size());
        if (const std::string_view item = user_data.substr(at, end - at); item.starts_with("typehash="))
            hash = item.substr(9);
        at = end + 1;
    }
    if (!hash)
        return {RangeLayout::Humble, "no typehash (Humble announces none)"};
    const std::string h(*hash);
    if (*hash == kRangeWithVariance)
        return {RangeLayout::Jazzy, "typehash " + h + ": Range with variance (Jazzy's)"};
    if (*hash == kRangeWithoutVariance)
        return {RangeLayout::Humble, "typehash " + h + ": Range without variance (Humble's fields)"};
    std::string shown;
    for (const char c : h.substr(0, 80)) // from the network: printable only, and short
        shown += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    return {std::nullopt, "typehash " + shown + ": no sensor_msgs/Range known here"};
}

RangeSubscribers::RangeSubscribers(dds_entity_t participant, const RosConfig& config, const SpokenDistro& distro)
    : config_(config), distro_(distro), topic_prefix_("rt" + ros_topic(config, "range/")), layout_(distro.layout) {
    reader_ = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr);
    if (reader_ < 0)
        throw std::runtime_error(std::string("DDS reader on DCPSSubscription: ") + dds_strretcode(reader_));
    choose();
}

RangeSubscribers::~RangeSubscribers() {
    if (reader_ > 0)
        dds_delete(reader_);
}

bool RangeSubscribers::update() {
    bool changed = false;
    constexpr int kBatch = 16;
    for (dds_return_t n = kBatch; n == kBatch;) {
        void* samples[kBatch] = {};
        dds_sample_info_t info[kBatch];
        n = dds_take(reader_, samples, info, kBatch, kBatch);
        for (dds_return_t i = 0; i < n; ++i) {
            const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
            std::array<uint8_t, 16> key;
            std::memcpy(key.data(), e->key.v, key.size());
            const auto it = subscribers_.find(key);
            if (!info[i].valid_data || info[i].instance_state != DDS_IST_ALIVE) {
                if (it != subscribers_.end()) {
                    std::fprintf(stderr, "caracara-ros: Range subscriber %s on %s left\n", it->second.gid.c_str(),
                                 it->second.topic.c_str() + 2);
                    subscribers_.erase(it);
                    changed = true;
                }
                continue;
            }
            const std::string topic = e->topic_name ? e->topic_name : "";
            const std::string_view number = std::string_view(topic).substr(std::min(topic.size(), topic_prefix_.size()));
            if (!topic.starts_with(topic_prefix_) || number.empty() ||
                !std::all_of(number.begin(), number.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
                !e->type_name || std::strcmp(e->type_name, kRangeTypeName) != 0)
                continue; // not a Range subscriber of this node's range/N
            void* data = nullptr;
            size_t size = 0;
            std::string user_data;
            if (e->qos && dds_qget_userdata(e->qos, &data, &size) && data) {
                user_data.assign(static_cast<const char*>(data), size);
                dds_free(data);
            }
            Subscriber s{topic, gid_text(e->key, distro_.layout), asked(user_data)};
            if (it != subscribers_.end() && it->second.asked.why == s.asked.why)
                continue;
            std::fprintf(stderr, "caracara-ros: Range subscriber %s on %s asks for %s: %s\n", s.gid.c_str(),
                         topic.c_str() + 2, s.asked.layout ? std::string(name_of(*s.asked.layout)).c_str() : "no layout known",
                         s.asked.why.c_str());
            subscribers_[key] = std::move(s);
            changed = true;
        }
        if (n > 0)
            dds_return_loan(reader_, samples, n);
    }
    const std::string before = why_;
    const RangeLayout layout = layout_;
    choose();
    if (layout_ != layout || why_ != before) {
        std::fprintf(stderr, "caracara-ros: Range in %s's layout: %s\n", std::string(name_of(layout_)).c_str(), why_.c_str());
        changed = true;
    }
    return changed;
}

void RangeSubscribers::choose() {
    const unsigned humble = count(RangeLayout::Humble), jazzy = count(RangeLayout::Jazzy);
    if (config_.range_layout_given) {
        layout_ = config_.range_layout;
        const unsigned others = layout_ == RangeLayout::Humble ? jazzy : humble;
        why_ = "range_layout in the config" +
               (others ? "; " + plural(others, "subscriber") + " asking for the other cannot read it" : std::string());
    } else if (humble && jazzy) {
        // The layout of more of them (on a tie, the one written already: no flapping). One writer
        // per topic reaches every subscriber, so the others cannot read Range: a setting to make.
        if (humble != jazzy)
            layout_ = humble > jazzy ? RangeLayout::Humble : RangeLayout::Jazzy;
        why_ = "Range subscribers asking for both (humble " + std::to_string(humble) + ", jazzy " +
               std::to_string(jazzy) + "): " + std::string(name_of(layout_)) +
               (humble != jazzy ? ", the more" : ", written already") +
               "; the others cannot read Range (set range_layout to choose)";
    } else if (humble || jazzy) {
        layout_ = humble ? RangeLayout::Humble : RangeLayout::Jazzy;
        why_ = "the Range subscribers' types: " + plural(humble + jazzy, "subscriber") + ", all asking for " +
               std::string(name_of(layout_));
    } else {
        // Nobody reads Range now: what the ROS 2 machines around speak, for the next one.
        layout_ = distro_.layout;
        why_ = "no Range subscriber: the distro spoken (" + distro_.why + ")";
    }
}

unsigned RangeSubscribers::count(std::optional<RangeLayout> layout) const {
    return static_cast<unsigned>(std::count_if(subscribers_.begin(), subscribers_.end(),
                                               [&](const auto& s) { return s.second.asked.layout == layout; }));
}

bool RangeSubscribers::warn() const {
    return count(std::nullopt) > 0 || count(layout_ == RangeLayout::Humble ? RangeLayout::Jazzy : RangeLayout::Humble) > 0;
}

std::vector<std::pair<std::string, std::string>> RangeSubscribers::values() const {
    std::vector<std::pair<std::string, std::string>> v{
        {"layout", std::string(name_of(layout_))},
        {"why", why_},
        {"humble subscribers", std::to_string(count(RangeLayout::Humble))},
        {"jazzy subscribers", std::to_string(count(RangeLayout::Jazzy))},
        {"unknown subscribers", std::to_string(count(std::nullopt))}};
    for (const auto& [key, s] : subscribers_)
        v.emplace_back("subscriber " + s.gid + " " + s.topic.substr(2),
                       (s.asked.layout ? std::string(name_of(*s.asked.layout)) : std::string("unknown")) + ": " + s.asked.why);
    return v;
}

} // namespace caracara::ros
