// The QoS profiles of rmw_qos_profile_t that caracara-ros's readers and writers use, every one
// XCDR1 as rmw_cyclonedds_cpp and rmw_fastrtps_cpp speak.
#pragma once

#include <dds/dds.h>

namespace caracara::ros {

enum class Profile {
    Default,        // reliable, volatile, keep-last 10 (rmw_qos_profile_default)
    Latched,        // reliable, transient-local, keep-last 1 (a late subscriber gets the state)
    SensorReader,   // best-effort, keep-last 5: matches reliable and best-effort writers alike
};

// A new QoS (the caller deletes it with dds_delete_qos).
dds_qos_t* qos_for(Profile profile);

} // namespace caracara::ros
