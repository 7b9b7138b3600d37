// Child processes for CLI tests: run a program to completion capturing stdout, stderr
// and the exit code, or keep one running (finsd) and read its first line. Every wait is
// bounded; a child still running at the end is killed, and so is one whose test binary
// died first (PR_SET_PDEATHSIG): an orphan finsd would hold its port into the next run.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <vector>

namespace fins::test {

struct RunResult {
    int exit_code = -1;
    std::string out;
    std::string err;
};

class Child {
  public:
    explicit Child(const std::vector<std::string>& argv) {
        int out[2];
        int err[2];
        if (::pipe(out) != 0 || ::pipe(err) != 0) return;
        const pid_t parent = ::getpid();
        pid_ = ::fork();
        if (pid_ == 0) {
            // prctl(2): the signal comes when the thread that forked ends; a parent that
            // died before the prctl has already reparented us, so check getppid() after.
            if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || ::getppid() != parent) ::_exit(127);
            ::dup2(out[1], 1);
            ::dup2(err[1], 2);
            ::close(out[0]);
            ::close(err[0]);
            std::vector<char*> args;
            for (const auto& a : argv)
                args.push_back(const_cast<char*>(a.c_str()));
            args.push_back(nullptr);
            ::execv(args[0], args.data());
            ::_exit(127);
        }
        ::close(out[1]);
        ::close(err[1]);
        out_fd_ = out[0];
        err_fd_ = err[0];
    }
    ~Child() {
        if (pid_ > 0 && !reaped_) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        if (out_fd_ >= 0) ::close(out_fd_);
        if (err_fd_ >= 0) ::close(err_fd_);
    }
    Child(const Child&) = delete;
    Child& operator=(const Child&) = delete;

    // Reads stdout up to the first newline, waiting at most `timeout`.
    std::string read_line(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
        return read_line_from(out_fd_, timeout);
    }
    // Reads stderr lines until one contains `text`; false after `timeout` or EOF.
    bool wait_for_stderr(const std::string& text,
                         std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < deadline) {
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                deadline - std::chrono::steady_clock::now());
            const auto line = read_line_from(err_fd_, left);
            if (line.find(text) != std::string::npos) return true;
            if (line.empty() && eof_) return false;
        }
        return false;
    }

  private:
    std::string read_line_from(int fd, std::chrono::milliseconds timeout) {
        std::string line;
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < deadline) {
            pollfd p{fd, POLLIN, 0};
            if (::poll(&p, 1, 100) <= 0) continue;
            char c = 0;
            if (::read(fd, &c, 1) != 1) {
                eof_ = true;
                break;
            }
            if (c == '\n') return line;
            line += c;
        }
        return line;
    }

  public:
    // Reads both pipes to EOF and reaps the child (bounded by `timeout`, then SIGKILL).
    RunResult wait(std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
        RunResult r;
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        bool out_open = true;
        bool err_open = true;
        while ((out_open || err_open) && std::chrono::steady_clock::now() < deadline) {
            pollfd p[2] = {{out_open ? out_fd_ : -1, POLLIN, 0},
                           {err_open ? err_fd_ : -1, POLLIN, 0}};
            if (::poll(p, 2, 100) <= 0) continue;
            char buf[4096];
            if (out_open && (p[0].revents & (POLLIN | POLLHUP))) {
                auto n = ::read(out_fd_, buf, sizeof buf);
                if (n <= 0)
                    out_open = false;
                else
                    r.out.append(buf, static_cast<std::size_t>(n));
            }
            if (err_open && (p[1].revents & (POLLIN | POLLHUP))) {
                auto n = ::read(err_fd_, buf, sizeof buf);
                if (n <= 0)
                    err_open = false;
                else
                    r.err.append(buf, static_cast<std::size_t>(n));
            }
        }
        if (out_open || err_open) ::kill(pid_, SIGKILL);
        int status = 0;
        ::waitpid(pid_, &status, 0);
        reaped_ = true;
        r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return r;
    }

    void terminate(int signal = SIGTERM) {
        if (pid_ > 0 && !reaped_) ::kill(pid_, signal);
    }
    [[nodiscard]] pid_t pid() const { return pid_; }

  private:
    pid_t pid_ = -1;
    int out_fd_ = -1;
    int err_fd_ = -1;
    bool reaped_ = false;
    bool eof_ = false;
};

inline RunResult run(const std::vector<std::string>& argv) {
    return Child(argv).wait();
}

}  // namespace fins::test
