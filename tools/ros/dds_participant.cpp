#include "tools/ros/dds_participant.hpp"

#include "tools/ros/enclave.hpp"

#include <cstdio>
#include <stdexcept>

namespace caracara::ros {

namespace {

std::string error(const char* what, dds_return_t r) { return std::string(what) + ": " + dds_strretcode(r); }

} // namespace

DdsParticipant::DdsParticipant(const RosConfig& c) {
    dds_domainid_t domain = c.domain_id;
    // The enclave first: a missing file is named before any DDS.
    std::unique_ptr<Enclave> enclave;
    if (!c.security.empty()) {
        const std::string module = AuditWatch::module_path();
        enclave = std::make_unique<Enclave>(c.security, c.security_plugins, module);
        audit_ = std::make_unique<AuditWatch>(module, c.security_plugins);
        if (!enclave->exposed().empty())
            std::fprintf(stderr, "caracara-ros: warning: %s is readable by every user of this machine (chmod 600 "
                                 "it, owned by caracara-ros)\n", enclave->exposed().front().c_str());
    }
    if (!c.interface.empty()) {
        // The one interface it may use, multicast on it (SPDP) even on a loopback interface.
        const std::string xml = "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"" +
                                c.interface + "\" multicast=\"true\"/></Interfaces></General></Domain></CycloneDDS>";
        domain_ = dds_create_domain(domain, xml.c_str());
        if (domain_ < 0)
            throw std::runtime_error(error(("DDS domain on interface " + c.interface).c_str(), domain_));
    }
    dds_qos_t* q = dds_create_qos();
    if (enclave)
        enclave->apply(q);
    // The enclave as rmw_cyclonedds announces it (`ros2 node info` groups by it).
    const std::string user_data = "enclave=" + (enclave ? enclave->name() : std::string("/")) + ";";
    dds_qset_userdata(q, user_data.data(), user_data.size());
    participant_ = dds_create_participant(domain, q, nullptr);
    dds_delete_qos(q);
    if (participant_ < 0) {
        if (domain_ > 0)
            dds_delete(domain_);
        // Cyclone has logged why (a certificate, a signature, a permission) just before.
        throw std::runtime_error(error(c.security.empty() ? "DDS participant"
                                                          : ("DDS participant with the enclave " + c.security).c_str(),
                                       participant_));
    }
    try {
        discovery_info_ = std::make_unique<DiscoveryInfo>(participant_, c);
    } catch (...) {
        dds_delete(participant_);
        if (domain_ > 0)
            dds_delete(domain_);
        throw;
    }
}

DdsParticipant::~DdsParticipant() {
    dds_delete(participant_);
    if (domain_ > 0)
        dds_delete(domain_);
}

void DdsParticipant::require_protected(const std::string& ros_name) const {
    if (audit_)
        audit_->require_protected("rt" + ros_name);
}

void DdsParticipant::watch(sd_event* event) {
    if (audit_)
        audit_->start(event, participant_);
}

dds_entity_t DdsParticipant::topic(const dds_topic_descriptor_t* desc, const std::string& ros_name) {
    const std::string name = "rt" + ros_name;
    const dds_entity_t t = dds_create_topic(participant_, desc, name.c_str(), nullptr, nullptr);
    if (t < 0)
        throw std::runtime_error(error(("DDS topic " + name).c_str(), t));
    return t;
}

dds_entity_t DdsParticipant::writer(const dds_topic_descriptor_t* desc, const std::string& ros_name, Profile p) {
    dds_qos_t* q = qos_for(p);
    const dds_entity_t w = dds_create_writer(participant_, topic(desc, ros_name), q, nullptr);
    dds_delete_qos(q);
    if (w < 0)
        throw std::runtime_error(error(("DDS writer on " + ros_name).c_str(), w));
    discovery_info_->add_writer(w);
    return w;
}

void DdsParticipant::delete_writer(dds_entity_t writer) {
    discovery_info_->remove_writer(writer);
    dds_delete(writer);
}

dds_entity_t DdsParticipant::reader(const dds_topic_descriptor_t* desc, const std::string& ros_name, Profile p,
                                    const dds_listener_t* listener) {
    dds_qos_t* q = qos_for(p);
    const dds_entity_t r = dds_create_reader(participant_, topic(desc, ros_name), q, listener);
    dds_delete_qos(q);
    if (r < 0)
        throw std::runtime_error(error(("DDS reader on " + ros_name).c_str(), r));
    discovery_info_->add_reader(r);
    return r;
}

} // namespace caracara::ros
