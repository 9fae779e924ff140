#include "tools/ros/static_frames.hpp"

#include "tools/ros/mirror_values.hpp"

#include <vector>

namespace caracara::ros {

StaticFrames::StaticFrames(DdsParticipant& dds, const RosConfig& config)
    : config_(config), writer_(dds.writer(&tf2_msgs_msg_dds__TFMessage__desc, "/tf_static", Profile::Latched)) {}

void StaticFrames::write(std::size_t ranges) {
    const std::vector<SensorMount> mounts = sensor_mounts(config_, ranges);
    std::vector<geometry_msgs_msg_dds__TransformStamped_> ts;
    const timespec now = realtime_now();
    for (const SensorMount& m : mounts) {
        const frames::Quaternion q = mount_rotation(m);
        ts.push_back({header(config_.base_frame, now), msg_str(m.frame), {{m.xyz.x, m.xyz.y, m.xyz.z}, {q.x, q.y, q.z, q.w}}});
    }
    // The headers and child frames point into `mounts`, alive until the write returns.
    tf2_msgs_msg_dds__TFMessage_ tf{};
    tf.transforms = {static_cast<uint32_t>(ts.size()), static_cast<uint32_t>(ts.size()), ts.data(), false};
    dds_write(writer_, &tf);
    written_ = true;
}

} // namespace caracara::ros
