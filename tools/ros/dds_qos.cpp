#include "tools/ros/dds_qos.hpp"

namespace caracara::ros {

dds_qos_t* qos_for(Profile p) {
    dds_qos_t* q = dds_create_qos();
    switch (p) {
    case Profile::Default:
        dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
        dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
        dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
        break;
    case Profile::Latched:
        dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
        dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
        dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
        break;
    case Profile::SensorReader:
        dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
        dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
        dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 5);
        break;
    }
    // XCDR1, as rmw_cyclonedds_cpp and rmw_fastrtps_cpp speak (XCDR2 is not what ROS 2 uses).
    const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
    dds_qset_data_representation(q, 1, xcdr1);
    return q;
}

} // namespace caracara::ros
