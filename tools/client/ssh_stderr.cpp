#include "tools/client/ssh_stderr.hpp"

#include <cerrno>
#include <condition_variable>
#include <fcntl.h>
#include <csignal>
#include <mutex>
#include <pthread.h>
#include <thread>
#include <unistd.h>

namespace caracara::client {

// The copying thread's state. It blocks in read() until ssh and everything it started have
// closed the pipe; a thread still blocked when caracaractl exits simply ends with it.
struct SshStderr::Relay {
    int read_fd = -1;
    int out_fd = -1; // caracaractl's own stderr (a duplicate, kept open by the thread)
    std::mutex mutex;
    std::condition_variable closed_cv;
    std::string said;
    bool closed = false;

    void run() {
        char buf[4096];
        for (;;) {
            const ssize_t n = read(read_fd, buf, sizeof buf);
            if (n < 0 && errno == EINTR)
                continue;
            if (n <= 0)
                break;
            for (ssize_t off = 0; off < n;) {
                const ssize_t w = write(out_fd, buf + off, static_cast<size_t>(n - off));
                if (w < 0 && errno == EINTR)
                    continue;
                if (w <= 0)
                    break; // caracaractl's stderr is gone: keep reading, so ssh never blocks
                off += w;
            }
            std::lock_guard lock(mutex);
            said.append(buf, static_cast<size_t>(n));
            constexpr size_t kKeep = 16384; // ssh says little; a chatty remote shell is cut
            if (said.size() > kKeep)
                said.erase(0, said.size() - kKeep);
        }
        close(read_fd);
        close(out_fd);
        std::lock_guard lock(mutex);
        closed = true;
        closed_cv.notify_all();
    }
};

int SshStderr::capture() {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) < 0)
        return -errno;
    saved_stderr_ = fcntl(STDERR_FILENO, F_DUPFD_CLOEXEC, 3);
    if (saved_stderr_ < 0 || dup2(fds[1], STDERR_FILENO) < 0) { // dup2 clears CLOEXEC on fd 2
        const int e = errno;
        close(fds[0]);
        close(fds[1]);
        if (saved_stderr_ >= 0)
            close(saved_stderr_);
        saved_stderr_ = -1;
        return -e;
    }
    close(fds[1]);
    relay_ = std::make_shared<Relay>();
    relay_->read_fd = fds[0];
    return 0;
}

void SshStderr::restore() {
    if (saved_stderr_ < 0)
        return;
    dup2(saved_stderr_, STDERR_FILENO); // drops our copy of the pipe's write end: ssh holds the last
    relay_->out_fd = saved_stderr_;
    saved_stderr_ = -1;
    // The thread takes no signals: SIGINT and SIGTERM are for the main thread's signalfd.
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    std::thread([relay = relay_] { relay->run(); }).detach();
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
}

std::string SshStderr::said(std::chrono::milliseconds timeout) {
    if (!relay_)
        return {};
    std::unique_lock lock(relay_->mutex);
    relay_->closed_cv.wait_for(lock, timeout, [&] { return relay_->closed; });
    return relay_->said;
}

SshStderr::~SshStderr() {
    restore(); // after a capture() whose open failed
    // ssh has been told to end (closing the bus sends it SIGTERM): let its last words through.
    if (relay_)
        said(std::chrono::milliseconds(300));
}

bool SshStderr::refused(const std::string& said) {
    // What the topside sees when the login is refused: ssh's own messages, nologin's, PAM's.
    for (const char* sign : {"Permission denied", "Host key verification failed", "REMOTE HOST IDENTIFICATION HAS CHANGED",
                             "Too many authentication failures", "no matching host key type",
                             "This account is currently not available", "account has expired"})
        if (said.find(sign) != std::string::npos)
            return true;
    return false;
}

} // namespace caracara::client
