// Which ROS 2 distro the machines around speak, read from their ros_discovery_info: rmw_dds_common's
// Gid is Humble's 24 bytes or, since Iron, 16, so a ParticipantEntitiesInfo parses in exactly one
// of the two layouts to its last byte (the other runs short or leaves bytes over). One reader on
// ros_discovery_info typed in Jazzy's layout, each sample taken as its raw CDR and parsed by size
// here: Cyclone checks a sample against the reader's type and drops (and logs) one that does not
// fit, and a Humble one fits Jazzy's (its Gid's last 8 bytes, zero as every rmw makes them, read
// as an empty node list) where a Jazzy one never fits Humble's. A peer counts while its writer is
// matched; caracara-ros's own is left out.
#pragma once

#include "tools/ros/ros_config.hpp"
#include "tools/ros/spoken_distro.hpp"

#include <array>
#include <cstdint>
#include <dds/dds.h>
#include <map>
#include <optional>
#include <span>

namespace caracara::ros {

class DistroDetector {
public:
    // Readers on `participant`'s ros_discovery_info; the owner takes what came with update(), on
    // its own loop. Throws std::runtime_error with Cyclone's message when they cannot be made.
    explicit DistroDetector(dds_entity_t participant);
    ~DistroDetector();
    DistroDetector(const DistroDetector&) = delete;
    DistroDetector& operator=(const DistroDetector&) = delete;

    // Takes what came; true when the count of peers of either distro changed.
    bool update();
    unsigned peers(RangeLayout distro) const;
    // The distro to speak from the peers' counts, and why, into `distro`: the peers' one, or where
    // both are about the more numerous (on a tie, the one spoken already: no flapping). False,
    // `distro` unchanged, when no peer is left.
    bool choose(SpokenDistro& distro) const;

    // The distro a ParticipantEntitiesInfo's CDR (encapsulation header included) is laid out in,
    // none when it parses in neither or both.
    static std::optional<RangeLayout> layout_of(std::span<const uint8_t> cdr);

private:
    dds_entity_t reader_ = 0;
    std::array<uint8_t, 12> own_prefix_{};
    std::map<dds_instance_handle_t, RangeLayout> peers_; // by the peer's ros_discovery_info writer
};

} // namespace caracara::ros
