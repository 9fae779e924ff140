// An SROS2 enclave (keystore/enclaves/<path>, as `ros2 security create_enclave` lays it out)
// turned into the DDS Security properties Cyclone's plugins take, as rmw_cyclonedds passes them
// (dds.sec.*, file: URIs): identity CA, certificate and key for authentication; permissions CA,
// signed governance and permissions for access control; the crypto plugin for encryption.
#pragma once

#include <dds/dds.h>
#include <string>
#include <utility>
#include <vector>

namespace caracara::ros {

class Enclave {
public:
    // Reads nothing but checks every file is there and readable: throws std::runtime_error naming
    // the first missing one. `plugins`: the directory of libdds_security_{auth,ac,crypto}.so;
    // `audit`: the module that wraps the authentication and access-control ones (audit_watch.hpp).
    Enclave(const std::string& dir, const std::string& plugins, const std::string& audit);

    // The enclave's name as ROS 2 gives it (the path under keystore/enclaves: "/caracara/ros"),
    // "/" when the directory is not under an enclaves/ directory.
    const std::string& name() const { return name_; }
    // Sets the properties on a participant's QoS.
    void apply(dds_qos_t* qos) const;
    // Files others than the owner and group may read (a private key should not be): for a warning.
    std::vector<std::string> exposed() const;

private:
    std::string dir_, name_;
    std::vector<std::pair<std::string, std::string>> props_;
};

} // namespace caracara::ros
