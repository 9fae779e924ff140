#include "tools/ros/enclave.hpp"

#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace caracara::ros {

namespace {

// Each file of an enclave and the property that names it (rmw_cyclonedds's mapping).
constexpr std::pair<const char*, const char*> kFiles[] = {
    {"identity_ca.cert.pem", "dds.sec.auth.identity_ca"},
    {"cert.pem", "dds.sec.auth.identity_certificate"},
    {"key.pem", "dds.sec.auth.private_key"},
    {"permissions_ca.cert.pem", "dds.sec.access.permissions_ca"},
    {"governance.p7s", "dds.sec.access.governance"},
    {"permissions.p7s", "dds.sec.access.permissions"},
};

} // namespace

Enclave::Enclave(const std::string& dir, const std::string& plugins, const std::string& audit) : dir_(dir) {
    while (dir_.size() > 1 && dir_.back() == '/')
        dir_.pop_back();
    const auto at = dir_.rfind("/enclaves/");
    name_ = at == std::string::npos ? "/" : dir_.substr(at + std::string("/enclaves").size());
    for (const auto& [file, prop] : kFiles) {
        const std::string path = dir_ + "/" + file;
        if (access(path.c_str(), R_OK) != 0)
            throw std::runtime_error("ros.security: " + path + " is missing or unreadable (an SROS2 enclave has " +
                                     "identity_ca.cert.pem, cert.pem, key.pem, permissions_ca.cert.pem, governance.p7s "
                                     "and permissions.p7s)");
        props_.emplace_back(prop, "file:" + path);
    }
    for (const char* kind : {"auth", "crypto", "access"}) {
        const std::string lib = plugins + "/libdds_security_" + (std::string(kind) == "access" ? "ac" : kind) + ".so";
        if (access(lib.c_str(), R_OK) != 0)
            throw std::runtime_error("DDS Security plugin " + lib + " is missing (Debian's libddsc0debian ships it)");
        const std::string init = std::string(kind) == "auth" ? "authentication"
                                 : std::string(kind) == "access" ? "access_control" : "crypto";
        // Authentication and access control through the audit module, which loads these itself.
        const bool audited = std::string(kind) != "crypto";
        const std::string prefix = audited ? "caracara_" : "";
        props_.emplace_back("dds.sec." + std::string(kind) + ".library.path", audited ? audit : lib);
        props_.emplace_back("dds.sec." + std::string(kind) + ".library.init", prefix + "init_" + init);
        props_.emplace_back("dds.sec." + std::string(kind) + ".library.finalize", prefix + "finalize_" + init);
    }
}

void Enclave::apply(dds_qos_t* qos) const {
    for (const auto& [k, v] : props_)
        dds_qset_prop(qos, k.c_str(), v.c_str());
}

std::vector<std::string> Enclave::exposed() const {
    struct stat st {};
    const std::string key = dir_ + "/key.pem";
    if (stat(key.c_str(), &st) == 0 && (st.st_mode & S_IROTH))
        return {key};
    return {};
}

} // namespace caracara::ros
