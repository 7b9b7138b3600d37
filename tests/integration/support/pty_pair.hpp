// A pseudo-terminal pair made by socat (`socat -d -d pty,raw,echo=0,link=DIR/a
// pty,raw,echo=0,link=DIR/b`), started by the test itself: two device paths, where bytes
// written to one come out of the other. Every wait is bounded; the destructor kills socat
// (SIGKILL by its pid) and reaps it. close() ends socat early to make a port vanish.
// Header-only, no gtest, so benchmarks and other helpers can use it too.
//
// The paths are symlinks in a directory of this pair's own, not /dev/pts/N: the kernel
// gives a freed pty number to the next pty opened, so under a parallel ctest a vanished
// /dev/pts/N is soon another test's device, and a program reopening it would find it
// again. A link removed by close() stays gone.
#pragma once

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>

namespace fins::test {

class PtyPair {
  public:
    // Starts socat and waits up to `timeout` for both "PTY is /dev/pts/N" lines and for
    // its "starting data transfer loop". ok() is false when that did not happen.
    explicit PtyPair(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
        char dir[] = "/tmp/finskit-pty-XXXXXX";
        if (::mkdtemp(dir) == nullptr) return;
        dir_ = dir;
        const std::string link_a = "pty,raw,echo=0,link=" + dir_ + "/a";
        const std::string link_b = "pty,raw,echo=0,link=" + dir_ + "/b";
        int err[2];
        if (::pipe(err) != 0) return;
        pid_ = ::fork();
        if (pid_ == 0) {
            ::dup2(err[1], 2);
            ::close(err[0]);
            ::close(err[1]);
            const char* argv[] = {"socat", "-d", "-d", link_a.c_str(), link_b.c_str(), nullptr};
            ::execvp("socat", const_cast<char* const*>(argv));
            ::_exit(127);
        }
        ::close(err[1]);
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        std::string line;
        int ptys = 0;
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
            if (line.find("PTY is ") != std::string::npos) ++ptys;
            if (line.find("starting data transfer loop") != std::string::npos) started = true;
            line.clear();
        }
        // socat logs nothing more at this level until it ends; an unread pipe could only
        // block it then, so stop listening.
        ::close(err[0]);
        if (ptys == 2) {
            a_ = dir_ + "/a";
            b_ = dir_ + "/b";
        }
        ok_ = started && ptys == 2 && ::access(a_.c_str(), F_OK) == 0 &&
              ::access(b_.c_str(), F_OK) == 0;
    }
    ~PtyPair() { close(); }
    PtyPair(const PtyPair&) = delete;
    PtyPair& operator=(const PtyPair&) = delete;

    [[nodiscard]] bool ok() const { return ok_; }
    [[nodiscard]] const std::string& a() const { return a_; }
    [[nodiscard]] const std::string& b() const { return b_; }

    // Ends socat: both devices disappear (their open ends see EOF/EIO), and so do their
    // links (socat, killed, cannot remove them itself).
    void close() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
            pid_ = -1;
        }
        if (dir_.empty()) return;
        ::unlink((dir_ + "/a").c_str());
        ::unlink((dir_ + "/b").c_str());
        ::rmdir(dir_.c_str());
        dir_.clear();
    }

  private:
    pid_t pid_ = -1;
    bool ok_ = false;
    std::string dir_;
    std::string a_;
    std::string b_;
};

}  // namespace fins::test
