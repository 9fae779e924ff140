#include "daemon/dive/dive_writer.hpp"

#include "daemon/loop/log.hpp"
#include "drivers/platform/dive_files.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace caracara {

DiveWriter::DiveWriter(std::string directory, uint64_t max_total_bytes)
    : dir_(std::move(directory)), max_total_(max_total_bytes) {}

DiveWriter::~DiveWriter() {
    {
        std::lock_guard lock(mu_);
        stopping_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable())
        thread_.join();
    if (fd_ >= 0)
        ::close(fd_);
}

void DiveWriter::start() {
    if (!thread_.joinable())
        thread_ = std::thread([this] { run(); });
}

void DiveWriter::push(Job j) {
    {
        std::lock_guard lock(mu_);
        queue_.push_back(std::move(j));
    }
    cv_.notify_one();
}

void DiveWriter::open(std::string name, std::vector<uint8_t> header) { push({Op::Open, std::move(name), std::move(header)}); }
void DiveWriter::append(std::vector<uint8_t> block) { push({Op::Append, {}, std::move(block)}); }
void DiveWriter::close() { push({Op::Close, {}, {}}); }

void DiveWriter::drain() {
    std::unique_lock lock(mu_);
    idle_cv_.wait(lock, [this] { return (queue_.empty() && !busy_) || !thread_.joinable(); });
}

void DiveWriter::run() {
    std::unique_lock lock(mu_);
    for (;;) {
        cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
        if (queue_.empty()) // stopping, and everything queued is written
            break;
        Job j = std::move(queue_.front());
        queue_.pop_front();
        busy_ = true;
        lock.unlock();
        switch (j.op) {
        case Op::Open: do_open(j); break;
        case Op::Append: do_append(j.bytes); break;
        case Op::Close: do_close(); break;
        }
        lock.lock();
        busy_ = false;
        if (queue_.empty())
            idle_cv_.notify_all();
    }
    idle_cv_.notify_all();
}

void DiveWriter::do_open(const Job& j) {
    do_close();
    total_ = 0;
    for (const DiveFile& f : list_dive_files(dir_))
        total_ += f.size;
    current_ = j.name;
    full_ = false;
    std::string path = dir_ + "/" + j.name;
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0640);
    if (fd_ < 0) {
        // Once per daemon run: a missing directory (no LogsDirectory=) is not worth a line a dive.
        if (!warned_open_)
            log_warning("dive recorder: cannot create %s: %s; dives are not recorded", path.c_str(),
                        std::strerror(errno));
        warned_open_ = true;
        current_.clear();
        return;
    }
    // The unit's UMask=0077 would leave it to the daemon's user alone; the caracara group reads
    // dives (caracaractl dives, plot), as LogsDirectoryMode=0750 lets it into the directory.
    ::fchmod(fd_, 0640);
    log_info("dive recorder: recording %s", path.c_str());
    do_append(j.bytes);
}

void DiveWriter::do_append(const std::vector<uint8_t>& bytes) {
    if (fd_ < 0 || full_)
        return;
    total_ += bytes.size();
    if (total_ > max_total_)
        rotate(bytes.size());
    if (total_ > max_total_) {
        full_ = true;
        log_warning("dive recorder: %s alone reached recorder.max_total_mb; the rest of this dive is not recorded",
                    current_.c_str());
        return;
    }
    if (!write_all(bytes)) {
        log_warning("dive recorder: writing %s/%s failed: %s; the rest of this dive is not recorded", dir_.c_str(),
                    current_.c_str(), std::strerror(errno));
        full_ = true;
        return;
    }
    // A crash or power cut loses at most the block being written (about a second).
    ::fdatasync(fd_);
    written_.fetch_add(bytes.size(), std::memory_order_relaxed);
}

bool DiveWriter::write_all(const std::vector<uint8_t>& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return false;
        done += static_cast<std::size_t>(n);
    }
    return true;
}

void DiveWriter::do_close() {
    if (fd_ >= 0)
        ::close(fd_);
    fd_ = -1;
    current_.clear();
}

void DiveWriter::rotate(uint64_t incoming) {
    std::vector<DiveFile> files = list_dive_files(dir_);
    total_ = incoming;
    for (const DiveFile& f : files)
        total_ += f.size;
    for (const DiveFile& f : files) {
        if (total_ <= max_total_ || f.name == current_)
            continue;
        if (::unlink(f.path.c_str()) == 0) {
            total_ -= f.size;
            rotated_.fetch_add(1, std::memory_order_relaxed);
            log_info("dive recorder: deleted %s (recorder.max_total_mb)", f.name.c_str());
        }
    }
}

} // namespace caracara
