#include "drivers/platform/dive_files.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <dirent.h>
#include <fcntl.h>
#include <string_view>
#include <sys/stat.h>
#include <unistd.h>

namespace caracara {

std::vector<DiveFile> list_dive_files(const std::string& directory, std::string* error) {
    std::vector<DiveFile> out;
    DIR* d = ::opendir(directory.c_str());
    if (!d) {
        if (error)
            *error = directory + ": " + std::strerror(errno);
        return out;
    }
    while (const dirent* e = ::readdir(d)) {
        const std::string_view name = e->d_name;
        if (!name.starts_with(kDivePrefix) || !name.ends_with(kDiveSuffix))
            continue;
        DiveFile f{std::string(name), directory + "/" + std::string(name), 0};
        struct stat st {};
        if (::stat(f.path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
            continue;
        f.size = static_cast<uint64_t>(st.st_size);
        out.push_back(std::move(f));
    }
    ::closedir(d);
    std::sort(out.begin(), out.end(), [](const DiveFile& a, const DiveFile& b) { return a.name < b.name; });
    return out;
}

bool read_whole_file(const std::string& path, std::vector<uint8_t>& out, std::string& error) {
    out.clear();
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        error = path + ": " + std::strerror(errno);
        return false;
    }
    uint8_t buf[65536];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            error = path + ": " + std::strerror(errno);
            ::close(fd);
            return false;
        }
        if (n == 0)
            break;
        out.insert(out.end(), buf, buf + n);
    }
    ::close(fd);
    return true;
}

std::string dive_file_name(uint64_t unix_ms) {
    const time_t secs = static_cast<time_t>(unix_ms / 1000);
    tm utc{};
    ::gmtime_r(&secs, &utc);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%S", &utc);
    char name[64];
    std::snprintf(name, sizeof name, "%s%s.%03uZ%s", kDivePrefix, stamp, static_cast<unsigned>(unix_ms % 1000),
                  kDiveSuffix);
    return name;
}

} // namespace caracara
