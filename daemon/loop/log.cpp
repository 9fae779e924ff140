#include "daemon/loop/log.hpp"

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/stat.h>
#include <systemd/sd-daemon.h>
#include <systemd/sd-journal.h>

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

namespace {
// systemd's convention: JOURNAL_STREAM names the device and inode of the journal stream that
// stderr was connected to; if stderr is still that stream, structured fields can go there.
bool stderr_is_journal() {
    const char* e = std::getenv("JOURNAL_STREAM");
    if (!e)
        return false;
    struct stat st {};
    if (fstat(2, &st) < 0)
        return false;
    unsigned long long dev = 0, ino = 0;
    if (std::sscanf(e, "%llu:%llu", &dev, &ino) != 2)
        return false;
    return st.st_dev == dev && st.st_ino == ino;
}
} // namespace

void log_thruster_fault(size_t thruster, std::string_view fault, bool appeared) {
    static const bool journal = stderr_is_journal();
    const std::string f(fault);
    const char* verb = appeared ? "raised" : "cleared";
    const int prio = appeared ? 4 : 5; // warning, notice
    if (journal) {
        sd_journal_send("MESSAGE=thruster %zu %s fault %s", thruster, verb, f.c_str(), "PRIORITY=%d", prio,
                        "THRUSTER=%zu", thruster, "FAULT=%s", f.c_str(), "FAULT_STATE=%s", appeared ? "on" : "off",
                        nullptr);
        return;
    }
    std::fprintf(stderr, "<%d>thruster %zu %s fault %s\n", prio, thruster, verb, f.c_str());
}

} // namespace caracara
