// The dive writer's rotation (daemon/dive_writer, docs/dive-format.md "How it is written"): when
// the directory passes its bound, the oldest dives go, as many as it takes and no more, never the
// one being written; a dive that alone passes the bound stops being recorded. Real files in a
// temporary directory, the writer's own thread.
#include "daemon/dive/dive_writer.hpp"
#include "drivers/platform/dive_files.hpp"
#include "tests/catch.hpp"

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

struct TempDir {
    std::string path;
    TempDir() {
        std::string t = (std::filesystem::temp_directory_path() / "caracara-dive-writer.XXXXXX").string();
        REQUIRE(::mkdtemp(t.data()) != nullptr);
        path = t;
    }
    ~TempDir() { std::filesystem::remove_all(path); }
};

std::vector<std::string> names(const std::string& dir) {
    std::vector<std::string> out;
    for (const auto& f : caracara::list_dive_files(dir))
        out.push_back(f.name);
    return out;
}

uint64_t total(const std::string& dir) {
    uint64_t n = 0;
    for (const auto& f : caracara::list_dive_files(dir))
        n += f.size;
    return n;
}

std::string dive(int n) { return "dive-20261125-0000" + std::to_string(10 + n) + ".cdive"; }

// One dive of `blocks` blocks of `size` bytes (the header is the first block).
void write_dive(caracara::DiveWriter& w, int n, int blocks, size_t size) {
    w.open(dive(n), std::vector<uint8_t>(size, 0xA5));
    for (int i = 1; i < blocks; ++i)
        w.append(std::vector<uint8_t>(size, static_cast<uint8_t>(i)));
    w.close();
    w.drain();
}

} // namespace

TEST_CASE("rotation by size: the oldest dives go, as many as needed to fit the bound") {
    TempDir d;
    caracara::DiveWriter w(d.path, 10'000);
    w.start();
    for (int n = 0; n < 4; ++n)
        write_dive(w, n, 3, 1000); // 3000 bytes each: three fit, the fourth does not
    // The fourth dive's third block sent the directory past the bound: the oldest dive went.
    CHECK(names(d.path) == std::vector<std::string>{dive(1), dive(2), dive(3)});
    CHECK(w.dives_rotated() == 1);
    write_dive(w, 4, 3, 1000);
    const auto left = names(d.path);
    CHECK(total(d.path) <= 10'000);
    // The count: exactly the oldest ones that had to go, the newest kept, the current one whole.
    REQUIRE(!left.empty());
    CHECK(left.back() == dive(4));
    CHECK(left.size() == 3);
    CHECK(left == std::vector<std::string>{dive(2), dive(3), dive(4)});
    CHECK(w.dives_rotated() == 2);
    CHECK(std::filesystem::file_size(d.path + "/" + dive(4)) == 3000);
}

TEST_CASE("rotation by count: many small dives, the bound holds and the newest survive") {
    TempDir d;
    caracara::DiveWriter w(d.path, 5'000);
    w.start();
    for (int n = 0; n < 40; ++n)
        write_dive(w, n, 2, 250); // 500 bytes each: ten fit
    const auto left = names(d.path);
    CHECK(total(d.path) <= 5'000);
    CHECK(left.size() == 10);
    CHECK(left.front() == dive(30));
    CHECK(left.back() == dive(39));
    CHECK(w.dives_rotated() == 30);
}

TEST_CASE("a dive that alone passes the bound: the others go first, then it stops being recorded") {
    TempDir d;
    caracara::DiveWriter w(d.path, 4'000);
    w.start();
    write_dive(w, 0, 2, 1000);
    write_dive(w, 1, 10, 1000); // 10000 bytes: more than the whole bound
    CHECK(names(d.path) == std::vector<std::string>{dive(1)});
    CHECK(w.dives_rotated() == 1);
    // What was written of it stays (a readable start); nothing past the bound.
    CHECK(std::filesystem::file_size(d.path + "/" + dive(1)) <= 4'000);
    CHECK(std::filesystem::file_size(d.path + "/" + dive(1)) >= 3'000);
    // The next dive is recorded again.
    write_dive(w, 2, 2, 1000);
    CHECK(names(d.path).back() == dive(2));
    CHECK(total(d.path) <= 4'000);
}
