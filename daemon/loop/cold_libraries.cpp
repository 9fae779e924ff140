#include "daemon/loop/cold_libraries.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <dirent.h>
#include <sys/mman.h>
#include <unistd.h>

namespace caracara {

namespace {

// libsystemd's (Debian 12 links them; later versions dlopen them on use), toml++ (read at
// start) and libm, 0.9 MiB of which the daemon calls lround() alone on its hot path (a command's
// values scaled; `nm -D --undefined-only caracarad`): its pages stay locked (kHotInCold).
// Nothing else on the loop, the workers or a kill calls into them.
constexpr std::string_view kCold[] = {"libgcrypt.so", "libgpg-error.so", "libzstd.so", "liblz4.so",
                                      "liblzma.so", "libcap.so", "libtomlplusplus.so", "libm.so"};
long (*const kHotInCold[])(double) = {&::lround};

// Threads of this process (/proc/self/task): another one could run into a hidden mapping.
int thread_count() {
    int n = 0;
    if (DIR* d = ::opendir("/proc/self/task")) {
        while (const dirent* e = ::readdir(d))
            n += e->d_name[0] != '.';
        ::closedir(d);
    }
    return n;
}

} // namespace

bool ColdLibraries::cold(std::string_view path) {
    const std::string_view name = path.substr(path.rfind('/') + 1);
    for (std::string_view c : kCold)
        if (name.substr(0, c.size()) == c)
            return true;
    return false;
}

void ColdLibraries::hide() {
    count_ = 0;
    std::FILE* f = std::fopen("/proc/self/smaps", "re");
    if (!f)
        return;
    // Read whole first, acted on after: changing a mapping while reading smaps would change it.
    Mapping current;
    bool candidate = false;
    char line[512];
    const auto close_mapping = [&] {
        if (candidate && count_ < std::size(cold_))
            cold_[count_++] = current;
        candidate = false;
    };
    while (std::fgets(line, sizeof line, f)) {
        unsigned long start = 0, end = 0, offset = 0;
        char perms[8] = {};
        int path_at = 0;
        if (std::sscanf(line, "%lx-%lx %7s %lx %*s %*s %n", &start, &end, perms, &offset, &path_at) == 4 &&
            path_at > 0) {
            close_mapping();
            std::string_view path(line + path_at);
            path = path.substr(0, path.find('\n'));
            // Read-only file pages only: a written one (relocations) exists nowhere else.
            candidate = perms[1] != 'w' && perms[0] == 'r' && !path.empty() && cold(path);
            // The first segment holds the symbol tables that the dynamic linker reads at every
            // lazy binding (mlockall's own, for one): never made inaccessible, only dropped after.
            current = {start, end, PROT_READ | (perms[2] == 'x' ? PROT_EXEC : 0), offset != 0};
        } else if (std::size_t kib = 0; candidate && std::sscanf(line, "Anonymous: %zu kB", &kib) == 1 && kib > 0) {
            candidate = false;
        }
    }
    close_mapping();
    std::fclose(f);
    const bool alone = thread_count() == 1; // else only dropped after the lock
    for (std::size_t i = 0; i < count_; ++i)
        if (!alone)
            cold_[i].hidden = false;
        else if (cold_[i].hidden)
            mprotect(reinterpret_cast<void*>(cold_[i].start), cold_[i].end - cold_[i].start, PROT_NONE);
}

std::size_t ColdLibraries::release() {
    std::size_t released = 0;
    for (std::size_t i = 0; i < count_; ++i) {
        void* at = reinterpret_cast<void*>(cold_[i].start);
        const std::size_t len = cold_[i].end - cold_[i].start;
        if (cold_[i].hidden)
            mprotect(at, len, cold_[i].prot);
        // Locked pages cannot be dropped: unlocked first (MCL_FUTURE still holds for new mappings).
        if (munlock(at, len) == 0 && madvise(at, len, MADV_DONTNEED) == 0)
            released += len / 1024;
    }
    count_ = 0;
    // A hot function in a cold library: faulted in and locked again, two pages (it may cross
    // a page boundary).
    const auto page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
    for (auto* hot : kHotInCold)
        if (mlock(reinterpret_cast<void*>(reinterpret_cast<uintptr_t>(hot) & ~(page - 1)), 2 * page) == 0)
            released -= std::min<std::size_t>(released, 2 * page / 1024);
    return released;
}

} // namespace caracara
