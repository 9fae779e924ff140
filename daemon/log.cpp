#include "daemon/log.hpp"

#include <cstdarg>
#include <cstdio>
#include <systemd/sd-daemon.h>

namespace caracara {

namespace {
void vlog(const char* prefix, const char* fmt, va_list ap) {
    char buf[1024];
    std::vsnprintf(buf, sizeof buf, fmt, ap);
    std::fprintf(stderr, "%s%s\n", prefix, buf);
}
} // namespace

#define LOG_FN(name, prefix)         \
    void name(const char* fmt, ...) { \
        va_list ap;                   \
        va_start(ap, fmt);            \
        vlog(prefix, fmt, ap);        \
        va_end(ap);                   \
    }

LOG_FN(log_error, SD_ERR)
LOG_FN(log_warning, SD_WARNING)
LOG_FN(log_notice, SD_NOTICE)
LOG_FN(log_info, SD_INFO)
#undef LOG_FN

} // namespace caracara
