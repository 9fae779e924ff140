// The shared libraries that the daemon maps but does not run on its hot path: libsystemd's own
// dependencies for journal files (compression, sealing), the configuration parser, and libm
// but for the one function the hot path calls. mlockall(MCL_CURRENT) would fault in and lock
// every page of every mapping, 3.5 MiB of these; around it, ColdLibraries keeps their
// read-only, never-written mappings out (the files' own pages, read from the page cache if
// ever needed). docs/realtime.md.
#pragma once

#include <cstddef>
#include <string_view>

namespace caracara {

class ColdLibraries {
public:
    // Whether the file mapped at `path` is one of them (by its name's stem: libzstd.so.1...).
    static bool cold(std::string_view path);

    // Before mlockall: the cold mappings found (/proc/self/smaps) and made inaccessible, which
    // mlockall does not fault in; none while another thread runs (it could run into one).
    void hide();
    // After mlockall: their access given back, unlocked, the pages they had dropped; the hot
    // functions in them locked. The KiB of mappings left unlocked.
    std::size_t release();

private:
    struct Mapping {
        unsigned long start = 0, end = 0;
        int prot = 0;
        bool hidden = false; // made inaccessible for mlockall
    };
    Mapping cold_[64];
    std::size_t count_ = 0;
};

} // namespace caracara
