#include "tools/ros/audit_watch.hpp"

#include <climits>
#include <cstdio>
#include <dlfcn.h>
#include <stdexcept>
#include <unistd.h>

namespace caracara::ros {

namespace {

// How long a discovered participant may go without beginning to authenticate (Cyclone validates
// a secure one's identity as it discovers it), and a begun authentication without ending (a
// handshake takes milliseconds; Cyclone resends its request for a peer that never answers).
constexpr auto kUnsecuredAfter = std::chrono::seconds(2);
constexpr double kUnauthenticatedAfterS = 5.0;

void log_refusal(const char* line) { std::fprintf(stderr, "caracara-ros: DDS Security: %s\n", line); }

void log_overdue(const char* guid) {
    std::fprintf(stderr, "caracara-ros: DDS Security: participant %s refused: not authenticated within %.0f s (an "
                         "identity from another CA, or ours refused by it)\n", guid, kUnauthenticatedAfterS);
}

std::string prefix_hex(const dds_guid_t& g) {
    static const char d[] = "0123456789abcdef";
    std::string s;
    for (int i = 0; i < 12; ++i)
        s += {d[g.v[i] >> 4], d[g.v[i] & 15]};
    return s;
}

} // namespace

std::string AuditWatch::module_path() {
    char exe[PATH_MAX];
    const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        std::string dir(exe, static_cast<std::size_t>(n));
        dir.erase(dir.rfind('/'));
        if (const std::string beside = dir + "/libcaracara_ros_audit.so"; access(beside.c_str(), R_OK) == 0)
            return beside;
    }
    return CARACARA_ROS_AUDIT_MODULE;
}

AuditWatch::AuditWatch(const std::string& module, const std::string& plugins) {
    lib_ = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib_)
        throw std::runtime_error("cannot load the DDS Security audit module " + module + ": " + dlerror());
    auto configure = reinterpret_cast<void (*)(const char*, void (*)(const char*))>(dlsym(lib_, "caracara_audit_configure"));
    overdue_ = reinterpret_cast<decltype(overdue_)>(dlsym(lib_, "caracara_audit_overdue"));
    known_ = reinterpret_cast<decltype(known_)>(dlsym(lib_, "caracara_audit_known"));
    open_ = reinterpret_cast<decltype(open_)>(dlsym(lib_, "caracara_audit_open"));
    if (!configure || !overdue_ || !known_ || !open_) {
        dlclose(lib_);
        throw std::runtime_error("the DDS Security audit module " + module + " is not caracara-ros's");
    }
    configure(plugins.c_str(), log_refusal);
}

AuditWatch::~AuditWatch() {
    timer_.reset();
    // The module stays loaded: Cyclone's participant, gone by now, held it too.
}

void AuditWatch::require_protected(const std::string& topic) const {
    static const char* const kWhy[] = {"", "it admits unauthenticated participants (allow_unauthenticated_participants)",
                                       "it does not control who writes on it (enable_write_access_control)",
                                       "no reader was made on it under DDS Security"};
    if (const int why = open_(topic.c_str()); why != 0)
        throw std::runtime_error("ros.security: the enclave's governance leaves " + topic + " open: " +
                                 kWhy[why < 4 ? why : 3] + "; a command topic takes only permitted writers");
}

void AuditWatch::start(sd_event* event, dds_entity_t participant) {
    dds_guid_t g{};
    dds_get_guid(participant, &g);
    own_ = prefix_hex(g);
    participants_ = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, nullptr, nullptr);
    if (participants_ < 0)
        throw std::runtime_error(std::string("DDS participant reader: ") + dds_strretcode(participants_));
    sd_event_source* s = nullptr;
    uint64_t now = 0;
    sd_event_now(event, CLOCK_MONOTONIC, &now);
    if (sd_event_add_time(event, &s, CLOCK_MONOTONIC, now + 1'000'000, 0, on_tick, this) < 0)
        throw std::runtime_error("cannot make the DDS Security watch's timer");
    timer_.reset(s);
}

int AuditWatch::on_tick(sd_event_source* s, uint64_t usec, void* userdata) {
    static_cast<AuditWatch*>(userdata)->tick();
    sd_event_source_set_time(s, usec + 1'000'000);
    sd_event_source_set_enabled(s, SD_EVENT_ON);
    return 0;
}

void AuditWatch::tick() {
    overdue_(kUnauthenticatedAfterS, log_overdue);
    const auto now = std::chrono::steady_clock::now();
    for (;;) {
        void* samples[16] = {};
        dds_sample_info_t info[16];
        const dds_return_t n = dds_take(participants_, samples, info, 16, 16);
        for (dds_return_t i = 0; i < n; ++i) {
            const std::string guid = prefix_hex(static_cast<const dds_builtintopic_participant_t*>(samples[i])->key);
            if (guid != own_ && info[i].instance_state == DDS_IST_ALIVE)
                unjudged_.try_emplace(guid, now);
        }
        if (n > 0)
            dds_return_loan(participants_, samples, n);
        if (n < 16)
            break;
    }
    for (auto it = unjudged_.begin(); it != unjudged_.end();) {
        if (known_(it->first.c_str())) {
            it = unjudged_.erase(it);
        } else if (now - it->second >= kUnsecuredAfter) {
            std::fprintf(stderr, "caracara-ros: DDS Security: participant %s refused: it has no DDS Security (the "
                                 "governance admits authenticated participants only)\n", it->first.c_str());
            it = unjudged_.erase(it);
        } else {
            ++it;
        }
    }
}

} // namespace caracara::ros
