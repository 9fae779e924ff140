// The DDS Security test peer: a Cyclone DDS participant with the real security plugins (Debian's
// libdds_security_auth, _ac, _crypto) and an SROS2 enclave, or none, as rmw_cyclonedds makes a
// ROS 2 node's (dds.sec.* properties, file: URIs). Its types idlc made from the ROS 2 message
// definitions as published (msg_to_idl.mjs), never from the project's IDL. Modes:
//   secure_peer ENCLAVE|rogue:ENCLAVE|none wrench FX FY FZ TX TY TZ HZ   a Wrench at HZ until killed
//   secure_peer ENCLAVE|rogue:ENCLAVE|none kill COUNT HZ                 COUNT std_msgs/Empty on kill, HZ apart
// rogue: its own access control lets it write whatever its permissions say (permissive_ac.c, the
// module PERMISSIVE), as a changed stack would; the vehicle still gets its real signed permissions.
// One JSON line when its writer's match count changes {"matched":N,"t_ns"}, and one per sample
// {"sent":I,"t_ns"} (CLOCK_MONOTONIC). It writes whether matched or not: a refused peer tries all
// the same. The plugins' directory is PLUGINS (the test's -D: where Debian puts them).
// Participant lease 1 s, so a killed peer leaves quickly.
#include "sp.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <dds/dds.h>
#include <string>
#include <thread>

namespace {

int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

dds_entity_t participant(std::string enclave) {
    dds_qos_t* q = dds_create_qos();
    const bool rogue = enclave.rfind("rogue:", 0) == 0;
    if (rogue)
        enclave = enclave.substr(6);
    if (enclave != "none") {
        const std::string plugins = PLUGINS;
        auto file = [&](const char* name) { return "file:" + enclave + "/" + name; };
        const std::pair<const char*, std::string> props[] = {
            {"dds.sec.auth.library.path", plugins + "/libdds_security_auth.so"},
            {"dds.sec.auth.library.init", "init_authentication"},
            {"dds.sec.auth.library.finalize", "finalize_authentication"},
            {"dds.sec.crypto.library.path", plugins + "/libdds_security_crypto.so"},
            {"dds.sec.crypto.library.init", "init_crypto"},
            {"dds.sec.crypto.library.finalize", "finalize_crypto"},
            {"dds.sec.access.library.path", plugins + "/libdds_security_ac.so"},
            {"dds.sec.access.library.init", "init_access_control"},
            {"dds.sec.access.library.finalize", "finalize_access_control"},
            {"dds.sec.auth.identity_ca", file("identity_ca.cert.pem")},
            {"dds.sec.auth.identity_certificate", file("cert.pem")},
            {"dds.sec.auth.private_key", file("key.pem")},
            {"dds.sec.access.permissions_ca", file("permissions_ca.cert.pem")},
            {"dds.sec.access.governance", file("governance.p7s")},
            {"dds.sec.access.permissions", file("permissions.p7s")},
        };
        for (const auto& [k, v] : props)
            dds_qset_prop(q, k, v.c_str());
        if (rogue) {
            dds_qset_prop(q, "dds.sec.access.library.path", PERMISSIVE);
            dds_qset_prop(q, "dds.sec.access.library.init", "init_permissive_access_control");
            dds_qset_prop(q, "dds.sec.access.library.finalize", "finalize_permissive_access_control");
        }
    }
    const char* env = std::getenv("ROS_DOMAIN_ID");
    const auto domain = static_cast<dds_domainid_t>(env ? std::atoi(env) : 0);
    // Loopback with multicast (the namespace's only interface), and a short lease.
    dds_create_domain(domain, "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\" "
                              "multicast=\"true\"/></Interfaces></General><Discovery><LeaseDuration>1s</LeaseDuration>"
                              "</Discovery></Domain></CycloneDDS>");
    const dds_entity_t p = dds_create_participant(domain, q, nullptr);
    dds_delete_qos(q);
    if (p < 0) {
        std::fprintf(stderr, "secure_peer: no participant: %s\n", dds_strretcode(p));
        std::exit(1);
    }
    return p;
}

dds_entity_t writer(dds_entity_t p, const dds_topic_descriptor_t* desc, const char* topic) {
    const dds_entity_t t = dds_create_topic(p, desc, topic, nullptr, nullptr);
    dds_qos_t* q = dds_create_qos();
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
    const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
    dds_qset_data_representation(q, 1, &xcdr1);
    const dds_entity_t w = dds_create_writer(p, t, q, nullptr);
    dds_delete_qos(q);
    if (w < 0) {
        std::fprintf(stderr, "secure_peer: no writer on %s: %s\n", topic, dds_strretcode(w));
        std::exit(1);
    }
    return w;
}

// Writes `sample` COUNT times (0: until killed) at `hz`, saying when the match count changes.
void run(dds_entity_t w, const void* sample, long count, double hz) {
    uint32_t matched = ~0u;
    const auto period = std::chrono::microseconds(static_cast<long>(1e6 / hz));
    for (long i = 0; count == 0 || i < count; ++i) {
        dds_publication_matched_status_t s{};
        dds_get_publication_matched_status(w, &s);
        if (s.current_count != matched) {
            matched = s.current_count;
            std::printf("{\"matched\":%u,\"t_ns\":%lld}\n", matched, static_cast<long long>(now_ns()));
        }
        const dds_return_t r = dds_write(w, sample);
        std::printf("{\"sent\":%ld,\"ok\":%s,\"t_ns\":%lld}\n", i, r == DDS_RETCODE_OK ? "true" : "false",
                    static_cast<long long>(now_ns()));
        std::fflush(stdout);
        std::this_thread::sleep_for(period);
    }
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 3)
        return 2;
    const std::string mode = argv[2];
    if (mode == "wrench" && argc == 10) {
        const dds_entity_t p = participant(argv[1]);
        const dds_entity_t w = writer(p, &geometry_msgs_msg_dds__Wrench__desc, "rt/caracara/cmd_wrench");
        geometry_msgs_msg_dds__Wrench_ s{{std::atof(argv[3]), std::atof(argv[4]), std::atof(argv[5])},
                                         {std::atof(argv[6]), std::atof(argv[7]), std::atof(argv[8])}};
        run(w, &s, 0, std::atof(argv[9]));
        return 0;
    }
    if (mode == "kill" && argc == 5) {
        const dds_entity_t p = participant(argv[1]);
        const dds_entity_t w = writer(p, &std_msgs_msg_dds__Empty__desc, "rt/caracara/kill");
        std_msgs_msg_dds__Empty_ s{0};
        run(w, &s, std::atol(argv[3]), std::atof(argv[4]));
        dds_delete(p);
        return 0;
    }
    return 2;
}
