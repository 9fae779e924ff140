/* The test's rogue peer: Debian's access-control plugin, except that it lets its own participant
 * write on any topic whatever its signed permissions say, as a stack changed by someone holding a
 * valid identity would. What the peer sends the vehicle is unchanged: its identity and its real
 * signed permissions; the vehicle's side must refuse the writer (test_ros.py). PLUGINS: the
 * directory of the real plugin (the test's -D). */
#include <dds/security/dds_security_api_access_control.h>

#include <dlfcn.h>
#include <stddef.h>

struct ddsi_domaingv;

static DDS_Security_boolean allow_datawriter(dds_security_access_control* instance, const DDS_Security_PermissionsHandle h,
                                             const DDS_Security_DomainId domain, const char* topic,
                                             const DDS_Security_Qos* qos, const DDS_Security_PartitionQosPolicy* partition,
                                             const DDS_Security_DataTags* tags, DDS_Security_SecurityException* ex) {
    (void)instance; (void)h; (void)domain; (void)topic; (void)qos; (void)partition; (void)tags; (void)ex;
    return 1;
}

static DDS_Security_boolean allow_topic(dds_security_access_control* instance, const DDS_Security_PermissionsHandle h,
                                        const DDS_Security_DomainId domain, const char* topic,
                                        const DDS_Security_Qos* qos, DDS_Security_SecurityException* ex) {
    (void)instance; (void)h; (void)domain; (void)topic; (void)qos; (void)ex;
    return 1;
}

static int (*real_finalize)(void*);

int init_permissive_access_control(const char* argument, void** context, struct ddsi_domaingv* gv) {
    void* lib = dlopen(PLUGINS "/libdds_security_ac.so", RTLD_NOW | RTLD_LOCAL);
    if (!lib)
        return -1;
    int (*init)(const char*, void**, struct ddsi_domaingv*) = (int (*)(const char*, void**, struct ddsi_domaingv*))dlsym(lib, "init_access_control");
    real_finalize = (int (*)(void*))dlsym(lib, "finalize_access_control");
    if (!init || !real_finalize || init(argument, context, gv) != 0)
        return -1;
    dds_security_access_control* ac = (dds_security_access_control*)*context;
    ac->check_create_datawriter = allow_datawriter;
    ac->check_create_topic = allow_topic;
    return 0;
}

int finalize_permissive_access_control(void* context) { return real_finalize(context); }
