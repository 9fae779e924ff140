// A generated type under another type name on the wire: the Jazzy layouts (sensor_msgs/Range,
// rmw_dds_common's Gid) live in an IDL module "jazzy" only so that both distros' layouts compile
// into one program. No XTypes type information, as for a type without one.
#pragma once

#include <dds/dds.h>

namespace caracara::ros {

inline dds_topic_descriptor_t under_type_name(const dds_topic_descriptor_t& d, const char* type_name) {
    return {d.m_size, d.m_align, d.m_flagset & ~DDS_TOPIC_XTYPES_METADATA, d.m_nkeys, type_name,
            d.m_keys, d.m_nops, d.m_ops, d.m_meta, {nullptr, 0}, {nullptr, 0}, d.restrict_data_representation};
}

} // namespace caracara::ros
