// The dive recorder's file side: a thread of its own that creates the dive files, appends the
// blocks the recorder hands it (about one a second) and deletes the oldest dives when the
// directory passes its size bound. The loop only queues; it never waits for the disk.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace caracara {

class DiveWriter {
public:
    DiveWriter(std::string directory, uint64_t max_total_bytes);
    ~DiveWriter();
    DiveWriter(const DiveWriter&) = delete;
    DiveWriter& operator=(const DiveWriter&) = delete;

    void start();
    // Each queues one step for the thread.
    void open(std::string name, std::vector<uint8_t> header);
    void append(std::vector<uint8_t> block);
    void close();
    // Blocks until everything queued is on disk (the daemon's shutdown).
    void drain();

    const std::string& directory() const { return dir_; }
    uint64_t bytes_written() const { return written_.load(std::memory_order_relaxed); }
    uint64_t dives_rotated() const { return rotated_.load(std::memory_order_relaxed); }

private:
    enum class Op { Open, Append, Close };
    struct Job {
        Op op;
        std::string name;
        std::vector<uint8_t> bytes;
    };
    void run();
    void do_open(const Job& j);
    void do_append(const std::vector<uint8_t>& bytes);
    void do_close();
    bool write_all(const std::vector<uint8_t>& bytes);
    // Deletes the oldest dives other than the one being written until the directory and the
    // `incoming` bytes fit.
    void rotate(uint64_t incoming);
    void push(Job j);

    const std::string dir_;
    const uint64_t max_total_;
    std::mutex mu_;
    std::condition_variable cv_;
    std::condition_variable idle_cv_;
    std::deque<Job> queue_;
    bool busy_ = false;
    bool stopping_ = false;
    std::thread thread_;

    // The thread's own state.
    int fd_ = -1;
    std::string current_;
    uint64_t total_ = 0;      // bytes of every dive in the directory, as last counted plus appends
    bool full_ = false;       // this dive alone passed the bound: the rest of it is dropped
    bool warned_open_ = false;
    std::atomic<uint64_t> written_{0};
    std::atomic<uint64_t> rotated_{0};
};

} // namespace caracara
