// The one child-process helper of the tests and benchmarks (CLI and finsd tests, the bridge
// tests' broker and bridges, bench/soak.cpp, bench/bridge_*.cpp). A child's stdout and
// stderr go either to pipes the test reads (read_line, wait_for_stderr; wait() collects the
// rest), or to a log file, so that a chatty child running long never blocks on a full pipe
// (read_line reads the log then; log() has all of it). Every wait is bounded; a child still
// running at the end is killed, and so is one whose parent died first (PR_SET_PDEATHSIG): an
// orphan finsd would hold its port into the next run.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace fins::test {

struct RunResult {
    int exit_code = -1;  // 128 + n when killed by signal n
    std::string out;
    std::string err;  // with a log file: the log
};

class Child {
  public:
    // stdout and stderr on pipes.
    explicit Child(const std::vector<std::string>& argv) {
        int out[2];
        int err[2];
        if (::pipe2(out, O_CLOEXEC) != 0) return;
        if (::pipe2(err, O_CLOEXEC) != 0) {
            ::close(out[0]);
            ::close(out[1]);
            return;
        }
        spawn(argv, out[1], err[1]);
        ::close(out[1]);
        ::close(err[1]);
        out_fd_ = out[0];
        err_fd_ = err[0];
    }
    // stdout and stderr both written to `log` (created or emptied).
    Child(const std::vector<std::string>& argv, std::filesystem::path log) : log_(std::move(log)) {
        const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd < 0) return;
        spawn(argv, fd, fd);
        ::close(fd);
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

    // The next line of stdout (with a log file: of the log), waiting at most `timeout`;
    // what there is (possibly empty) at the timeout or the end.
    std::string read_line(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
        if (!log_.empty()) return read_log_line(timeout);
        return read_line_from(out_fd_, timeout);
    }
    // Reads stderr lines (with a log file: the log's) until one contains `text`; false after
    // `timeout` or at the end. Each line read is added to `seen` when it is given.
    bool wait_for_stderr(const std::string& text,
                         std::chrono::milliseconds timeout = std::chrono::seconds(20),
                         std::vector<std::string>* seen = nullptr) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < deadline) {
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                deadline - std::chrono::steady_clock::now());
            const auto line = log_.empty() ? read_line_from(err_fd_, left) : read_log_line(left);
            if (seen != nullptr && !line.empty()) seen->push_back(line);
            if (line.find(text) != std::string::npos) return true;
            if (line.empty() && eof_) return false;
        }
        return false;
    }

    // Waits for the exit (bounded by `timeout`, then SIGKILL) and reaps the child: its exit
    // code, and what it wrote (the pipes read to their end, or the log).
    RunResult wait(std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
        RunResult r;
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        bool out_open = out_fd_ >= 0;
        bool err_open = err_fd_ >= 0;
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
        r.exit_code = reap(deadline);
        if (!log_.empty()) r.err = log();
        return r;
    }

    // Sends `signal` and reaps the child (SIGKILL after `timeout`): its exit code.
    int kill(int signal, std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
        terminate(signal);
        return reap(std::chrono::steady_clock::now() + timeout);
    }
    // Sends `signal` and returns (wait() or kill() reap it).
    void terminate(int signal = SIGTERM) {
        if (pid_ > 0 && !reaped_) ::kill(pid_, signal);
    }
    // False once it has exited (and then it is reaped: exit_code() holds how).
    bool running() {
        if (pid_ <= 0 || reaped_) return false;
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) != pid_) return true;
        reaped(status);
        return false;
    }
    // How it ended, once reaped (-1 before).
    [[nodiscard]] int exit_code() const { return exit_code_; }
    [[nodiscard]] pid_t pid() const { return pid_; }
    // Everything in the log file so far (empty with pipes).
    [[nodiscard]] std::string log() const {
        std::ifstream in(log_, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), {}};
    }

  private:
    void spawn(const std::vector<std::string>& argv, int out_fd, int err_fd) {
        const pid_t parent = ::getpid();
        pid_ = ::fork();
        if (pid_ != 0) return;
        // prctl(2): the signal comes when the thread that forked ends; a parent that died
        // before the prctl has already reparented us, so check getppid() after.
        if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || ::getppid() != parent) ::_exit(127);
        ::dup2(out_fd, 1);  // dup2 clears O_CLOEXEC on 1 and 2
        ::dup2(err_fd, 2);
        std::vector<char*> args;
        for (const auto& a : argv)
            args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        ::execv(args[0], args.data());
        ::_exit(127);
    }

    void reaped(int status) {
        reaped_ = true;
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    // Reaps the child, SIGKILL at `deadline`: its exit code.
    int reap(std::chrono::steady_clock::time_point deadline) {
        while (running() && std::chrono::steady_clock::now() < deadline)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        if (pid_ > 0 && !reaped_) {
            ::kill(pid_, SIGKILL);
            int status = 0;
            ::waitpid(pid_, &status, 0);
            reaped(status);
        }
        return exit_code_;
    }

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
    // The log from where the last line ended up to the next newline; polls the file
    // (bounded) until one comes or the child has exited.
    std::string read_log_line(std::chrono::milliseconds timeout) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        for (;;) {
            const bool exited = !running();
            const std::string all = log();
            const auto end = all.find('\n', log_read_);
            if (end != std::string::npos) {
                std::string line = all.substr(log_read_, end - log_read_);
                log_read_ = end + 1;
                return line;
            }
            if (exited || std::chrono::steady_clock::now() >= deadline) {
                eof_ = exited;
                std::string rest = all.size() > log_read_ ? all.substr(log_read_) : "";
                log_read_ = all.size();
                return rest;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
    }

    pid_t pid_ = -1;
    int out_fd_ = -1;
    int err_fd_ = -1;
    std::filesystem::path log_;
    std::size_t log_read_ = 0;
    bool reaped_ = false;
    int exit_code_ = -1;
    bool eof_ = false;
};

inline RunResult run(const std::vector<std::string>& argv) {
    return Child(argv).wait();
}

}  // namespace fins::test
