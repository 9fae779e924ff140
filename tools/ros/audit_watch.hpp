// What caracara-ros says about the peers DDS Security refuses: it loads the audit module
// (security_audit.cpp, Cyclone's authentication and access-control plugins wrapped) before the
// participant, so each refusal the plugins decide is logged at once; and once a second it logs the
// peers Cyclone drops without a word: a participant with no DDS Security (governance admits only
// authenticated ones) and one whose authentication never ended (its identity from another CA,
// or ours refused there). Each once, with its GUID prefix.
#pragma once

#include "drivers/sdbus/sdbus.hpp"

#include <chrono>
#include <dds/dds.h>
#include <map>
#include <string>

namespace caracara::ros {

class AuditWatch {
public:
    // Loads the module at `module` and points it at the real plugins in `plugins`; throws
    // std::runtime_error when it cannot.
    AuditWatch(const std::string& module, const std::string& plugins);
    AuditWatch(const AuditWatch&) = delete;
    AuditWatch& operator=(const AuditWatch&) = delete;
    ~AuditWatch();

    // Watches the participant's peers on `event`, from now on.
    void start(sd_event* event, dds_entity_t participant);

    // Throws std::runtime_error when the governance lets a writer the permissions do not allow
    // reach our reader on `topic` (a DDS topic name): unauthenticated participants admitted, or
    // no write access control on it. A command topic must be closed to them.
    void require_protected(const std::string& topic) const;

    // The module found for this executable: next to it (a build tree), else where it is installed.
    static std::string module_path();

private:
    static int on_tick(sd_event_source* s, uint64_t usec, void* userdata);
    void tick();

    void* lib_ = nullptr;
    void (*overdue_)(double, void (*)(const char*)) = nullptr;
    bool (*known_)(const char*) = nullptr;
    int (*open_)(const char*) = nullptr;
    dds_entity_t participants_ = 0;
    std::string own_;
    caracara::SourcePtr timer_;
    // Participants seen on discovery and not yet judged, with when they were first seen.
    std::map<std::string, std::chrono::steady_clock::time_point> unjudged_;
};

} // namespace caracara::ros
