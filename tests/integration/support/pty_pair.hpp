// A pseudo-terminal pair made by socat (`socat -d -d pty,raw,echo=0 pty,raw,echo=0`),
// started by the test itself: two device paths, where bytes written to one come out of
// the other. Every wait is bounded; the destructor kills socat (SIGKILL by its pid) and
// reaps it. close() ends socat early to make a port vanish. Header-only, no gtest, so
// benchmarks and other helpers can use it too.
#pragma once

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>

namespace fins::test {

class PtyPair {
  public:
    // Starts socat and waits up to `timeout` for both "PTY is /dev/pts/N" lines and for
    // its "starting data transfer loop". ok() is false when that did not happen.
    explicit PtyPair(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
        int err[2];
        if (::pipe(err) != 0) return;
        pid_ = ::fork();
        if (pid_ == 0) {
            ::dup2(err[1], 2);
            ::close(err[0]);
            ::close(err[1]);
            const char* argv[] = {"socat", "-d", "-d", "pty,raw,echo=0", "pty,raw,echo=0", nullptr};
            ::execvp("socat", const_cast<char* const*>(argv));
            ::_exit(127);
        }
        ::close(err[1]);
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        std::string line;
        bool started = false;
        while (!started && std::chrono::steady_clock::now() < deadline) {
            pollfd p{err[0], POLLIN, 0};
            if (::poll(&p, 1, 100) <= 0) continue;
            char c = 0;
            if (::read(err[0], &c, 1) != 1) break;
            if (c != '\n') {
                line += c;
                continue;
            }
            const auto at = line.find("PTY is ");
            if (at != std::string::npos) (a_.empty() ? a_ : b_) = line.substr(at + 7);
            if (line.find("starting data transfer loop") != std::string::npos) started = true;
            line.clear();
        }
        // socat logs nothing more at this level until it ends; an unread pipe could only
        // block it then, so stop listening.
        ::close(err[0]);
        ok_ = started && !a_.empty() && !b_.empty();
    }
    ~PtyPair() { close(); }
    PtyPair(const PtyPair&) = delete;
    PtyPair& operator=(const PtyPair&) = delete;

    [[nodiscard]] bool ok() const { return ok_; }
    [[nodiscard]] const std::string& a() const { return a_; }
    [[nodiscard]] const std::string& b() const { return b_; }

    // Ends socat: both devices disappear (their open ends see EOF/EIO).
    void close() {
        if (pid_ <= 0) return;
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
        pid_ = -1;
    }

  private:
    pid_t pid_ = -1;
    bool ok_ = false;
    std::string a_;
    std::string b_;
};

}  // namespace fins::test
