// daemon/loop/ColdLibraries around mlockall, as ThreadSchedule::lock_memory uses it, judged from
// the kernel's side (/proc/self/smaps): the libraries off the hot path (libsystemd's compression
// and crypto, toml++, libm) are mapped but not locked, but for the page(s) of lround(), the one
// libm function the hot path calls; everything else is locked; the cold libraries still run.
#include "daemon/loop/cold_libraries.hpp"

#include "tests/catch.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <cstring>
#include <sys/mman.h>
#include <unistd.h>
#include <vector>

using namespace caracara;

namespace {

struct Mapping {
    std::string path;
    std::string perms;
    std::size_t kib = 0;
    bool locked = false; // VmFlags "lo"
};

std::vector<Mapping> mappings() {
    std::vector<Mapping> out;
    std::ifstream f("/proc/self/smaps");
    std::string line;
    while (std::getline(f, line)) {
        std::istringstream in(line);
        std::string range, perms, offset, dev, inode, path;
        in >> range >> perms;
        if (const std::size_t dash = range.find('-'); dash != std::string::npos && range.back() != ':' && perms.size() == 4) {
            in >> offset >> dev >> inode >> path;
            const std::size_t bytes = std::stoul(range.substr(dash + 1), nullptr, 16) - std::stoul(range.substr(0, dash), nullptr, 16);
            out.push_back({path, perms, bytes / 1024, false});
        } else if (!out.empty() && range == "VmFlags:") {
            // Not "Locked:", which is the locked pages' proportional share: a libm page that ten
            // other processes map counts a tenth, 0 kB once rounded (this test failed so while
            // CI's other tests ran).
            out.back().locked = (" " + line + " ").find(" lo ") != std::string::npos;
        }
    }
    return out;
}

std::string file_name(const std::string& path) { return path.substr(path.rfind('/') + 1); }

// KiB of locked mappings (mlock's VM_LOCKED) of the code of the library whose file name starts
// with `stem`: its executable mappings. Its data (the writable segment, the relocated read-only
// one) is written memory that mlockall keeps locked, as it must.
std::size_t locked_kib(const std::vector<Mapping>& maps, const std::string& stem, bool* mapped = nullptr) {
    std::size_t kib = 0;
    for (const Mapping& m : maps)
        if (file_name(m.path).rfind(stem, 0) == 0 && m.perms[2] == 'x') {
            kib += m.locked ? m.kib : 0;
            if (mapped)
                *mapped = true;
        }
    return kib;
}

} // namespace

TEST_CASE("ColdLibraries: cold by the file name's stem, wherever the library lives") {
    CHECK(ColdLibraries::cold("/usr/lib/x86_64-linux-gnu/libzstd.so.1.5.4"));
    CHECK(ColdLibraries::cold("/lib/aarch64-linux-gnu/liblzma.so.5"));
    CHECK(ColdLibraries::cold("/usr/lib/x86_64-linux-gnu/libgcrypt.so.20"));
    CHECK(ColdLibraries::cold("/usr/lib/x86_64-linux-gnu/libtomlplusplus.so.3"));
    CHECK(ColdLibraries::cold("/lib/x86_64-linux-gnu/libm.so.6"));
    CHECK(ColdLibraries::cold("libcap.so.2"));
    // Not cold: what the loop, the workers and a kill run.
    CHECK_FALSE(ColdLibraries::cold("/lib/x86_64-linux-gnu/libc.so.6"));
    CHECK_FALSE(ColdLibraries::cold("/lib/x86_64-linux-gnu/libsystemd.so.0"));
    CHECK_FALSE(ColdLibraries::cold("/lib/x86_64-linux-gnu/libstdc++.so.6"));
    CHECK_FALSE(ColdLibraries::cold("/lib/x86_64-linux-gnu/libmd.so.0")); // libm's stem, not libm
    CHECK_FALSE(ColdLibraries::cold("/opt/libm.so.6/libc.so.6"));         // the file's name decides
}

TEST_CASE("ColdLibraries: around mlockall the cold libraries stay unlocked but lround's pages; they still run") {
    ColdLibraries cold;
    cold.hide();
    const int locked = mlockall(MCL_CURRENT);
    const int error = errno;
    const std::size_t left_out = cold.release();
    // The cold libraries run after their access was given back.
    volatile double x = 0.5;
    CHECK(std::lround(x * 10) == 5);
    CHECK(std::cos(x) == Approx(0.8775825619));
#if CARACARA_TEST_EMULATED || CARACARA_TEST_ASAN
    // qemu-user maps the arm64 program's code as data it translates, and AddressSanitizer makes
    // mlock a no-op (caracarad never locks under it): which libraries are locked is judged on
    // the native, unsanitized builds (as e2e test_realtime does).
    (void)left_out;
    if (locked == 0)
        munlockall();
    WARN("the cold libraries' locking: not judged under an emulator or AddressSanitizer");
    return;
#endif
    const auto maps = mappings();
    if (locked == 0)
        munlockall();
    const std::size_t page_kib = std::size_t(sysconf(_SC_PAGESIZE)) / 1024;
    bool libm = false;
    const std::size_t libm_locked = locked_kib(maps, "libm.so", &libm);
    REQUIRE(libm);
    if (locked != 0 && error == EPERM) {
        // Locking refused outright (systemd-nspawn's seccomp filter denies mlock too, as in
        // the Debian 13 root of tests/system/debian13.sh): nothing is locked, lround's pages
        // neither; what is left to see is the access given back (above).
        CHECK(libm_locked == 0);
        return;
    }
    CHECK(libm_locked > 0);             // lround()'s page(s), locked again
    CHECK(libm_locked <= 2 * page_kib); // and nothing more of libm
    if (locked != 0) {
        // Where this process may not lock everything (a container holding RLIMIT_MEMLOCK without
        // CAP_IPC_LOCK, where caracarad leaves memory unlocked too: test_thread_schedule), what
        // is left to see is the above: access given back, lround's pages locked.
        INFO("mlockall: " << std::strerror(error));
        CHECK((error == ENOMEM || error == EPERM));
        return;
    }
    CHECK(left_out > 0);
    for (const char* stem : {"libzstd.so", "liblz4.so", "liblzma.so", "libgcrypt.so", "libcap.so"}) {
        INFO(stem);
        CHECK(locked_kib(maps, stem) == 0);
    }
    // The rest is locked: libc's and this program's own code.
    CHECK(locked_kib(maps, "libc.so") > 0);
    bool self = false;
    CHECK(locked_kib(maps, "test_cold_libraries", &self) > 0);
    CHECK(self);
}
