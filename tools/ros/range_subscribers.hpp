// The sensor_msgs/Range layout each subscriber of range/N asks for, and the one caracara-ros
// writes. Humble and Jazzy give Range the same DDS type name (sensor_msgs::msg::dds_::Range_) and
// neither sends XTypes type information Cyclone 0.10 reads; what tells them apart is the type hash
// Iron and later put in each endpoint's USER_DATA ("typehash=RIHS01_<sha256>;", rmw_dds_common's
// encoding, the hash of the type's description as rosidl computes it). Jazzy's Range (with
// variance) has one hash, the Range without it another; Humble sends none. Read from the
// DCPSSubscription built-in topic, so a subscriber is seen before any Range writer exists.
// The layout: the config's range_layout when it names one; else the subscribers' (the more of
// them where both are about, a tie keeping what is written); with none, the distro spoken
// (DistroDetector's). Each subscriber that comes or leaves is logged with what it asks and why.
#pragma once

#include "tools/ros/ros_config.hpp"
#include "tools/ros/spoken_distro.hpp"

#include <array>
#include <dds/dds.h>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace caracara::ros {

class RangeSubscribers {
public:
    // What a subscriber's USER_DATA asks for: a layout (none: a type hash of no Range known here)
    // and why, as the journal says it.
    struct Asked {
        std::optional<RangeLayout> layout;
        std::string why;
    };
    static Asked asked(std::string_view user_data);

    // Throws std::runtime_error with Cyclone's message when the built-in reader cannot be made.
    RangeSubscribers(dds_entity_t participant, const RosConfig& config, const SpokenDistro& distro);
    ~RangeSubscribers();
    RangeSubscribers(const RangeSubscribers&) = delete;
    RangeSubscribers& operator=(const RangeSubscribers&) = delete;

    // Takes what discovery brought and chooses again (the spoken distro may have changed too);
    // true when a subscriber came or left or the choice changed.
    bool update();
    RangeLayout layout() const { return layout_; }
    const std::string& why() const { return why_; }
    // Some subscriber asks for what is not written, or for a Range not known here.
    bool warn() const;
    // /diagnostics' values: the layout, why, the count of each, each subscriber and what it asks.
    std::vector<std::pair<std::string, std::string>> values() const;

private:
    struct Subscriber {
        std::string topic;
        std::string gid; // as `ros2 topic info -v` prints it
        Asked asked;
    };
    unsigned count(std::optional<RangeLayout> layout) const;
    void choose();

    const RosConfig& config_;
    const SpokenDistro& distro_;
    dds_entity_t reader_ = 0;
    std::string topic_prefix_; // "rt/caracara/range/"
    std::map<std::array<uint8_t, 16>, Subscriber> subscribers_; // by the reader's GUID
    RangeLayout layout_;
    std::string why_;
};

} // namespace caracara::ros
