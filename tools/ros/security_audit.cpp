// caracara-ros's DDS Security audit: a plugin module Cyclone loads in place of Debian's
// authentication and access-control plugins (dds.sec.{auth,access}.library.path). It loads the
// real ones, hands Cyclone their own function tables, and wraps only the calls that decide on a
// remote participant or writer, to log each refusal: Cyclone logs them at trace level only (a
// protected topic's name is "sensitive"), or not at all on the side whose peer gave up. Every
// decision stays the real plugin's; this module only reads its answers.
// Only the two plugin interfaces: dds_security_api.h brings in Cyclone's internals, C only.
#include <dds/security/dds_security_api_access_control.h>
#include <dds/security/dds_security_api_authentication.h>

#include <chrono>
#include <cstdio>
#include <dlfcn.h>
#include <map>
#include <mutex>
#include <string>

namespace {

using Clock = std::chrono::steady_clock;
using Log = void (*)(const char* line);

struct Remote {
    std::string guid;
    Clock::time_point since;
    bool done = false; // authenticated or already logged as refused
};

std::mutex mutex;
std::string plugins;
Log log_line = nullptr;
std::map<DDS_Security_IdentityHandle, Remote> remotes;      // by remote identity handle
std::map<DDS_Security_HandshakeHandle, DDS_Security_IdentityHandle> handshakes;

DDS_Security_authentication_validate_remote_identity real_validate_remote_identity;
DDS_Security_authentication_begin_handshake_request real_begin_handshake_request;
DDS_Security_authentication_begin_handshake_reply real_begin_handshake_reply;
DDS_Security_authentication_process_handshake real_process_handshake;
DDS_Security_access_control_validate_remote_permissions real_validate_remote_permissions;
DDS_Security_access_control_check_remote_datawriter real_check_remote_datawriter;
DDS_Security_access_control_check_remote_participant real_check_remote_participant;
DDS_Security_access_control_get_participant_sec_attributes real_get_participant_sec_attributes;
DDS_Security_access_control_get_datareader_sec_attributes real_get_datareader_sec_attributes;

// What the governance makes of this participant and of its readers, for caracara_audit_open().
bool unauthenticated_allowed = false;
std::map<std::string, bool> reader_write_protected; // by topic

struct Real {
    void* lib = nullptr;
    int (*init)(const char*, void**, struct ddsi_domaingv*) = nullptr;
    int (*finalize)(void*) = nullptr;
};
Real auth, access_control;

std::string hex(const unsigned char* b, std::size_t n) {
    static const char d[] = "0123456789abcdef";
    std::string s;
    for (std::size_t i = 0; i < n; ++i)
        s += {d[b[i] >> 4], d[b[i] & 15]};
    return s;
}

std::string guid_of(const DDS_Security_GUID_t& g) { return hex(g.prefix, sizeof g.prefix); }

std::string guid_of(const DDS_Security_BuiltinTopicKey_t& k) {
    return hex(reinterpret_cast<const unsigned char*>(k), 12);
}

void say(const std::string& line) {
    if (log_line)
        log_line(line.c_str());
}

std::string why(const DDS_Security_SecurityException* ex) {
    return ex && ex->message ? std::string(ex->message) : std::string("no reason given");
}

// A handshake step's result: a failure is logged once, with the participant and the plugin's reason.
DDS_Security_ValidationResult_t judged(DDS_Security_IdentityHandle remote, DDS_Security_ValidationResult_t r,
                                       const DDS_Security_SecurityException* ex) {
    std::lock_guard l(mutex);
    auto it = remotes.find(remote);
    if (it == remotes.end() || it->second.done)
        return r;
    if (r == DDS_SECURITY_VALIDATION_FAILED) {
        it->second.done = true;
        say("participant " + it->second.guid + " refused: authentication failed: " + why(ex));
    } else if (r == DDS_SECURITY_VALIDATION_OK || r == DDS_SECURITY_VALIDATION_OK_FINAL_MESSAGE) {
        it->second.done = true;
        say("participant " + it->second.guid + " authenticated");
    }
    return r;
}

DDS_Security_ValidationResult_t validate_remote_identity(
    dds_security_authentication* instance, DDS_Security_IdentityHandle* remote_identity_handle,
    DDS_Security_AuthRequestMessageToken* local_auth_request_token,
    const DDS_Security_AuthRequestMessageToken* remote_auth_request_token,
    const DDS_Security_IdentityHandle local_identity_handle, const DDS_Security_IdentityToken* remote_identity_token,
    const DDS_Security_GUID_t* remote_participant_guid, DDS_Security_SecurityException* ex) {
    const auto r = real_validate_remote_identity(instance, remote_identity_handle, local_auth_request_token,
                                                 remote_auth_request_token, local_identity_handle,
                                                 remote_identity_token, remote_participant_guid, ex);
    const std::string guid = guid_of(*remote_participant_guid);
    if (r == DDS_SECURITY_VALIDATION_FAILED) {
        say("participant " + guid + " refused: its identity token: " + why(ex));
    } else {
        std::lock_guard l(mutex);
        remotes.try_emplace(*remote_identity_handle, Remote{guid, Clock::now()});
    }
    return r;
}

DDS_Security_ValidationResult_t begin_handshake_request(dds_security_authentication* instance,
                                                        DDS_Security_HandshakeHandle* handshake_handle,
                                                        DDS_Security_HandshakeMessageToken* handshake_message,
                                                        const DDS_Security_IdentityHandle initiator_identity_handle,
                                                        const DDS_Security_IdentityHandle replier_identity_handle,
                                                        const DDS_Security_OctetSeq* serialized_local_participant_data,
                                                        DDS_Security_SecurityException* ex) {
    const auto r = real_begin_handshake_request(instance, handshake_handle, handshake_message, initiator_identity_handle,
                                                replier_identity_handle, serialized_local_participant_data, ex);
    if (r != DDS_SECURITY_VALIDATION_FAILED) {
        std::lock_guard l(mutex);
        handshakes[*handshake_handle] = replier_identity_handle;
    }
    return judged(replier_identity_handle, r, ex);
}

DDS_Security_ValidationResult_t begin_handshake_reply(dds_security_authentication* instance,
                                                      DDS_Security_HandshakeHandle* handshake_handle,
                                                      DDS_Security_HandshakeMessageToken* handshake_message_out,
                                                      const DDS_Security_HandshakeMessageToken* handshake_message_in,
                                                      const DDS_Security_IdentityHandle initiator_identity_handle,
                                                      const DDS_Security_IdentityHandle replier_identity_handle,
                                                      const DDS_Security_OctetSeq* serialized_local_participant_data,
                                                      DDS_Security_SecurityException* ex) {
    const auto r = real_begin_handshake_reply(instance, handshake_handle, handshake_message_out, handshake_message_in,
                                              initiator_identity_handle, replier_identity_handle,
                                              serialized_local_participant_data, ex);
    if (r != DDS_SECURITY_VALIDATION_FAILED) {
        std::lock_guard l(mutex);
        handshakes[*handshake_handle] = initiator_identity_handle;
    }
    return judged(initiator_identity_handle, r, ex);
}

DDS_Security_ValidationResult_t process_handshake(dds_security_authentication* instance,
                                                  DDS_Security_HandshakeMessageToken* handshake_message_out,
                                                  const DDS_Security_HandshakeMessageToken* handshake_message_in,
                                                  const DDS_Security_HandshakeHandle handshake_handle,
                                                  DDS_Security_SecurityException* ex) {
    const auto r = real_process_handshake(instance, handshake_message_out, handshake_message_in, handshake_handle, ex);
    DDS_Security_IdentityHandle remote = 0;
    {
        std::lock_guard l(mutex);
        if (const auto it = handshakes.find(handshake_handle); it != handshakes.end())
            remote = it->second;
    }
    return judged(remote, r, ex);
}

DDS_Security_PermissionsHandle validate_remote_permissions(
    dds_security_access_control* instance, const dds_security_authentication* auth_plugin,
    const DDS_Security_IdentityHandle local_identity_handle, const DDS_Security_IdentityHandle remote_identity_handle,
    const DDS_Security_PermissionsToken* remote_permissions_token,
    const DDS_Security_AuthenticatedPeerCredentialToken* remote_credential_token, DDS_Security_SecurityException* ex) {
    const auto h = real_validate_remote_permissions(instance, auth_plugin, local_identity_handle, remote_identity_handle,
                                                    remote_permissions_token, remote_credential_token, ex);
    if (h == DDS_SECURITY_HANDLE_NIL) {
        std::lock_guard l(mutex);
        const auto it = remotes.find(remote_identity_handle);
        say("participant " + (it == remotes.end() ? std::string("?") : it->second.guid) +
            " refused: its permissions: " + why(ex));
    }
    return h;
}

DDS_Security_boolean check_remote_participant(dds_security_access_control* instance,
                                              const DDS_Security_PermissionsHandle permissions_handle,
                                              const DDS_Security_DomainId domain_id,
                                              const DDS_Security_ParticipantBuiltinTopicDataSecure* participant_data,
                                              DDS_Security_SecurityException* ex) {
    const bool ok = real_check_remote_participant(instance, permissions_handle, domain_id, participant_data, ex);
    if (!ok)
        say("participant " + guid_of(participant_data->key) + " refused: its permissions do not let it join domain " +
            std::to_string(domain_id) + ": " + why(ex));
    return ok;
}

DDS_Security_boolean check_remote_datawriter(dds_security_access_control* instance,
                                             const DDS_Security_PermissionsHandle permissions_handle,
                                             const DDS_Security_DomainId domain_id,
                                             const DDS_Security_PublicationBuiltinTopicDataSecure* publication_data,
                                             DDS_Security_SecurityException* ex) {
    const bool ok = real_check_remote_datawriter(instance, permissions_handle, domain_id, publication_data, ex);
    if (!ok)
        say("writer of participant " + guid_of(publication_data->participant_key) + " on " +
            (publication_data->topic_name ? publication_data->topic_name : "?") +
            " refused: its signed permissions do not allow publishing it: " + why(ex));
    return ok;
}

DDS_Security_boolean get_participant_sec_attributes(dds_security_access_control* instance,
                                                    const DDS_Security_PermissionsHandle permissions_handle,
                                                    DDS_Security_ParticipantSecurityAttributes* attributes,
                                                    DDS_Security_SecurityException* ex) {
    const bool ok = real_get_participant_sec_attributes(instance, permissions_handle, attributes, ex);
    if (ok) {
        std::lock_guard l(mutex);
        unauthenticated_allowed = attributes->allow_unauthenticated_participants;
    }
    return ok;
}

DDS_Security_boolean get_datareader_sec_attributes(dds_security_access_control* instance,
                                                   const DDS_Security_PermissionsHandle permissions_handle,
                                                   const DDS_Security_char* topic_name,
                                                   const DDS_Security_PartitionQosPolicy* partition,
                                                   const DDS_Security_DataTagQosPolicy* data_tag,
                                                   DDS_Security_EndpointSecurityAttributes* attributes,
                                                   DDS_Security_SecurityException* ex) {
    const bool ok =
        real_get_datareader_sec_attributes(instance, permissions_handle, topic_name, partition, data_tag, attributes, ex);
    if (ok && topic_name) {
        std::lock_guard l(mutex);
        reader_write_protected[topic_name] = attributes->is_write_protected;
    }
    return ok;
}

// The plugin's entry `slot` kept as `real`, `ours` called in its place.
template <typename F>
void wrap(F& slot, F& real, F ours) {
    real = slot;
    slot = ours;
}

// Loads the real plugin `file` and runs its `init`: the table it makes is in *context.
int init_real(Real& real, const char* file, const char* init, const char* finalize, const char* argument,
              void** context, struct ddsi_domaingv* gv) {
    const std::string path = plugins + "/" + file;
    real.lib = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!real.lib) {
        say(std::string("cannot load ") + path + ": " + dlerror());
        return -1;
    }
    real.init = reinterpret_cast<decltype(real.init)>(dlsym(real.lib, init));
    real.finalize = reinterpret_cast<decltype(real.finalize)>(dlsym(real.lib, finalize));
    if (!real.init || !real.finalize)
        return -1;
    return real.init(argument, context, gv);
}

} // namespace

extern "C" {

// Before the participant: where the real plugins are, and where refusals go.
__attribute__((visibility("default"))) void caracara_audit_configure(const char* plugins_dir, Log log) {
    std::lock_guard l(mutex);
    plugins = plugins_dir;
    log_line = log;
}

// Calls `each` once for every remote participant whose authentication began `seconds` or more
// ago and has not ended (its peer gave up: an identity from another CA, or ours refused there).
__attribute__((visibility("default"))) void caracara_audit_overdue(double seconds, Log each) {
    std::lock_guard l(mutex);
    for (auto it = remotes.begin(); it != remotes.end();) {
        Remote& r = it->second;
        if (!r.done && Clock::now() - r.since >= std::chrono::duration<double>(seconds)) {
            r.done = true;
            each(r.guid.c_str());
        }
        // Judged long ago: forgotten, so peers coming and going do not grow the table.
        if (r.done && Clock::now() - r.since > std::chrono::minutes(1)) {
            std::erase_if(handshakes, [&](const auto& h) { return h.second == it->first; });
            it = remotes.erase(it);
        } else
            ++it;
    }
}

// Why a reader of ours on `topic` (a DDS topic name) would take samples from a writer its
// permissions do not allow: 0 none (authenticated writers only, their permissions checked), 1
// the governance admits unauthenticated participants, 2 it does not control who writes on the
// topic, 3 no such reader was made under security.
__attribute__((visibility("default"))) int caracara_audit_open(const char* topic) {
    std::lock_guard l(mutex);
    const auto it = reader_write_protected.find(topic);
    if (it == reader_write_protected.end())
        return 3;
    if (unauthenticated_allowed)
        return 1;
    return it->second ? 0 : 2;
}

// Whether a remote participant (its 12-byte GUID prefix, hex) has begun authenticating.
__attribute__((visibility("default"))) bool caracara_audit_known(const char* guid) {
    std::lock_guard l(mutex);
    for (const auto& [_, r] : remotes)
        if (r.guid == guid)
            return true;
    return false;
}

__attribute__((visibility("default"))) int caracara_init_authentication(const char* argument, void** context,
                                                                         struct ddsi_domaingv* gv) {
    if (const int r = init_real(auth, "libdds_security_auth.so", "init_authentication", "finalize_authentication",
                                argument, context, gv);
        r != 0)
        return r;
    auto* a = static_cast<dds_security_authentication*>(*context);
    wrap(a->validate_remote_identity, real_validate_remote_identity, validate_remote_identity);
    wrap(a->begin_handshake_request, real_begin_handshake_request, begin_handshake_request);
    wrap(a->begin_handshake_reply, real_begin_handshake_reply, begin_handshake_reply);
    wrap(a->process_handshake, real_process_handshake, process_handshake);
    return 0;
}

__attribute__((visibility("default"))) int caracara_finalize_authentication(void* context) {
    return auth.finalize(context);
}

__attribute__((visibility("default"))) int caracara_init_access_control(const char* argument, void** context,
                                                                         struct ddsi_domaingv* gv) {
    if (const int r = init_real(access_control, "libdds_security_ac.so", "init_access_control",
                                "finalize_access_control", argument, context, gv);
        r != 0)
        return r;
    auto* a = static_cast<dds_security_access_control*>(*context);
    wrap(a->validate_remote_permissions, real_validate_remote_permissions, validate_remote_permissions);
    wrap(a->check_remote_participant, real_check_remote_participant, check_remote_participant);
    wrap(a->check_remote_datawriter, real_check_remote_datawriter, check_remote_datawriter);
    wrap(a->get_participant_sec_attributes, real_get_participant_sec_attributes, get_participant_sec_attributes);
    wrap(a->get_datareader_sec_attributes, real_get_datareader_sec_attributes, get_datareader_sec_attributes);
    return 0;
}

__attribute__((visibility("default"))) int caracara_finalize_access_control(void* context) {
    return access_control.finalize(context);
}

} // extern "C"
