// `finsd ctl` against a running finsd (issue 18): the CPU Unit selector --plc in a plant
// of two, the default socket shared with finsd ($FINSD_SOCKET), and --timeout in
// seconds as `fins --timeout`. Every wait is bounded (process.hpp).
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "finsd/control_setup.hpp"
#include "integration/support/finsd_process.hpp"
#include "integration/support/raw_socket.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// Plant item: `finsd ctl` reached only the first [[plc]]. --plc NAME or NET.NODE picks
// any CPU Unit; without it, the first.
TEST(FinsdCtl, PlcSelectsACpuUnitOfAPlantOfTwo) {
    ScratchDir dir("ctlplant");
    const std::string socket = (dir.path() / "ctl.sock").string();
    const auto config = dir.write("plant.toml", "control = \"" + socket + R"("
[[plc]]
name = "press"
  [[plc.ethernet]]
  network = 1
  bind = "127.0.1.1"
  port = 0
[[plc]]
name = "oven"
  [[plc.ethernet]]
  network = 1
  bind = "127.0.1.2"
  port = 0
)");
    Finsd d({"--config", config});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(ctl(socket, {"--plc", "oven", "mode", "program"}).exit_code, 0);
    EXPECT_EQ(ctl(socket, {"fal", "3", "--plc", "1.2"}).exit_code, 0);
    const auto oven = ctl(socket, {"status", "--plc", "oven"});
    ASSERT_EQ(oven.exit_code, 0) << oven.err;
    const Json o = Json::parse(oven.out, nullptr, false);
    EXPECT_EQ(o["status"]["plc"], "oven");
    EXPECT_EQ(o["status"]["mode"], "program");
    EXPECT_EQ(o["status"]["error_code"], "4103");
    const Json p = Json::parse(ctl(socket, {"status"}).out, nullptr, false);
    EXPECT_EQ(p["status"]["plc"], "press");
    EXPECT_EQ(p["status"]["mode"], "run");
    EXPECT_EQ(p["status"]["error_code"], "0000");
    const auto unknown = ctl(socket, {"status", "--plc", "mixer"});
    EXPECT_EQ(unknown.exit_code, 2);
    EXPECT_TRUE(has(unknown.err, "no CPU Unit \"mixer\" here (CPU Units: press, oven)"))
        << unknown.err;
    EXPECT_EQ(d.stop().exit_code, 0);
}

// Plant item, W596 3: `finsd ctl --plc NAME send` runs on that CPU Unit's own instruction
// engine (it used to answer "no network instructions" in a plant): each CPU Unit sends
// its own words to the other, over FINS/UDP on their fixed loopback addresses.
TEST(FinsdCtl, W596_3_SendRunsOnTheCpuUnitPlcNames) {
    const FixedPorts fixed_ports;  // 127.0.82.x:9611 (finsd_run.hpp)
    ScratchDir dir("ctlsend");
    const std::string socket = (dir.path() / "ctl.sock").string();
    const auto config = dir.write("plant.toml", "control = \"" + socket + R"("
[[plc]]
name = "press"
  [[plc.ethernet]]
  network = 1
  node = 1
  bind = "127.0.82.1"
  port = 9611
[[plc]]
name = "oven"
  [[plc.ethernet]]
  network = 1
  node = 2
  bind = "127.0.82.2"
  port = 9611
)");
    Finsd d({"--config", config});
    ASSERT_TRUE(d.started()) << d.result().err;
    const std::string fins = std::string(FINS_BIN_DIR) + "/fins";
    const auto at = [&](const std::string& host, const std::string& dest,
                        std::vector<std::string> args) {
        std::vector<std::string> argv{fins,     "--host", host,        "--port", "9611",
                                      "--dest", dest,     "--timeout", "5"};
        argv.insert(argv.end(), args.begin(), args.end());
        return run(argv);
    };
    ASSERT_EQ(at("127.0.82.2", "1.2.0", {"write", "D0", "7", "8"}).exit_code, 0);
    const auto sent = ctl(socket, {"--plc", "oven", "send", "--dest", "1.1.0", "--local", "D0",
                                   "--remote", "D100", "--count", "2"});
    ASSERT_EQ(sent.exit_code, 0) << sent.out << sent.err;
    EXPECT_TRUE(has(sent.out, "wrote 2 words")) << sent.out;
    EXPECT_EQ(at("127.0.82.1", "1.1.0", {"read", "D100", "2"}).out, "D100  7\nD101  8\n");
    ASSERT_EQ(ctl(socket, {"--plc", "press", "send", "--dest", "1.2.0", "--local", "D100",
                           "--remote", "D300", "--count", "2"})
                  .exit_code,
              0);
    EXPECT_EQ(at("127.0.82.2", "1.2.0", {"read", "D300", "2"}).out, "D300  7\nD301  8\n");
    EXPECT_EQ(d.stop().exit_code, 0);
}

// Newcomer 6: finsd and finsd ctl find the socket the same way, $FINSD_SOCKET first.
TEST(FinsdCtl, Newcomer6_FinsdAndCtlShareTheDefaultSocket) {
    ScratchDir dir("ctldefault");
    const std::string socket = (dir.path() / "default.sock").string();
    Finsd d({}, {.env = {"FINSD_SOCKET=" + socket}});
    ASSERT_TRUE(d.started()) << d.result().err;
    const auto r = run({"/usr/bin/env", "FINSD_SOCKET=" + socket, finsd_path, "ctl", "status"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(has(r.out, "\"ok\":true")) << r.out;
    EXPECT_EQ(d.stop().exit_code, 0);

    // The rule itself: FINSD_SOCKET, else XDG_RUNTIME_DIR, else /run/finsd (root) or
    // /tmp/finsd-UID.
    const char* saved = std::getenv("FINSD_SOCKET");
    const std::string before = saved != nullptr ? saved : "";
    ::setenv("FINSD_SOCKET", "/tmp/x.sock", 1);
    EXPECT_EQ(finsd::default_control_socket(), "/tmp/x.sock");
    EXPECT_EQ(finsd::default_control_sockets(), std::vector<std::filesystem::path>{"/tmp/x.sock"});
    ::unsetenv("FINSD_SOCKET");
    const char* xdg = std::getenv("XDG_RUNTIME_DIR");
    const std::filesystem::path own =
        ::geteuid() == 0
            ? std::filesystem::path("/run/finsd/finsd.sock")
            : std::filesystem::path("/tmp/finsd-" + std::to_string(::geteuid())) / "finsd.sock";
    if (xdg == nullptr || *xdg == '\0') {
        EXPECT_EQ(finsd::default_control_socket(), own);
        EXPECT_EQ(finsd::default_control_sockets(), std::vector<std::filesystem::path>{own});
    } else {
        const auto first = std::filesystem::path(xdg) / "finsd.sock";
        EXPECT_EQ(finsd::default_control_socket(), first);
        EXPECT_EQ(finsd::default_control_sockets(),
                  (std::vector<std::filesystem::path>{first, own}));
    }
    if (!before.empty()) ::setenv("FINSD_SOCKET", before.c_str(), 1);
}

// Issue 26 point 8: finsd started as the docs show it (no --control, no FINSD_SOCKET)
// has a control channel, and `finsd ctl status` as the docs show it reaches it: both use
// $XDG_RUNTIME_DIR/finsd.sock (a scratch one here, so runs do not collide).
TEST(FinsdCtl, Issue26_8_FinsdAndCtlMeetAtTheDefaultSocketWithoutFlags) {
    ScratchDir dir("ctlxdg");
    const std::string xdg = "XDG_RUNTIME_DIR=" + dir.path().string();
    Finsd d({}, {.log_level = "", .env = {"-u", "FINSD_SOCKET", xdg}});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_TRUE(std::filesystem::is_socket(dir.path() / "finsd.sock"));
    const auto r = run({"/usr/bin/env", "-u", "FINSD_SOCKET", xdg, finsd_path, "ctl", "status"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(has(r.out, "\"ok\":true")) << r.out;
    const auto end = d.stop();
    EXPECT_EQ(end.exit_code, 0);
    EXPECT_TRUE(has(end.err, "control channel on " + (dir.path() / "finsd.sock").string()))
        << end.err;
}

// Issue 26 point 8: with no finsd at the default places, `finsd ctl` names the place and
// says how to start finsd with a control channel (the exact flag).
// A finsd another test (or a user) runs may hold /run/finsd/finsd.sock or /tmp/finsd-UID:
// as root the command runs in its own mount namespace with empty /run and /tmp, so that
// no default place holds a socket.
TEST(FinsdCtl, Issue26_8_CtlErrorSaysHowToStartFinsdWithAChannel) {
    ScratchDir dir("ctlnone");
    std::vector<std::string> command{
        "/usr/bin/env", "-u",  "FINSD_SOCKET", "XDG_RUNTIME_DIR=" + dir.path().string(),
        finsd_path,     "ctl", "status"};
    if (::geteuid() == 0 && ::access("/usr/bin/unshare", X_OK) == 0) {
        std::string line = "mount -t tmpfs none /run && mount -t tmpfs none /tmp && exec";
        for (const auto& word : command)
            line += " '" + word + "'";
        command = {
            "/usr/bin/unshare", "--mount", "--propagation", "private", "/bin/sh", "-c", line};
    }
    const auto r = run(command);
    EXPECT_NE(r.exit_code, 0);
    // The first default place that holds a socket, else the first: a stale socket another
    // run left at /run/finsd or /tmp/finsd-UID may be named instead of the scratch one.
    EXPECT_TRUE(has(r.err, "finsd ctl: cannot connect to ")) << r.err;
    EXPECT_TRUE(has(r.err, "`finsd --control PATH`")) << r.err;
    EXPECT_TRUE(has(r.err, "FINSD_SOCKET=PATH")) << r.err;
}

// Issue 26 point 8: the directory finsd creates for its default socket (/run/finsd for
// root, /tmp/finsd-UID otherwise) is created with its mode and refused when it is a link,
// not a directory, open to others or (root only can arrange it) owned by someone else.
TEST(FinsdCtl, Issue26_8_SocketDirectoryIsCreatedAndCheckedBeforeUse) {
    ScratchDir dir("ctldir");
    const uid_t me = ::geteuid();
    const auto fresh = dir.path() / "finsd-fresh";
    EXPECT_EQ(finsd::prepare_socket_directory(fresh, 0700, me), "");
    struct stat st {};
    ASSERT_EQ(::lstat(fresh.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 07777, 0700u);
    EXPECT_EQ(finsd::prepare_socket_directory(fresh, 0700, me), "");  // again: still fine

    const auto shared = dir.path() / "finsd-shared";
    ASSERT_EQ(::mkdir(shared.c_str(), 0700), 0);
    ASSERT_EQ(::chmod(shared.c_str(), 0777), 0);
    EXPECT_TRUE(has(finsd::prepare_socket_directory(shared, 0700, me), "has mode 0777"));
    ASSERT_EQ(::chmod(shared.c_str(), 0755), 0);
    EXPECT_TRUE(has(finsd::prepare_socket_directory(shared, 0700, me), "has mode 0755"));
    EXPECT_EQ(finsd::prepare_socket_directory(shared, 0755, me), "");  // /run/finsd's mode

    const auto link = dir.path() / "finsd-link";
    std::filesystem::create_directory_symlink(fresh, link);
    EXPECT_TRUE(has(finsd::prepare_socket_directory(link, 0700, me), "is a symbolic link"));
    const auto file = dir.write("finsd-file", "x");
    EXPECT_TRUE(has(finsd::prepare_socket_directory(file, 0700, me), "is not a directory"));

    EXPECT_TRUE(has(finsd::prepare_socket_directory(fresh, 0700, me + 1),
                    "is owned by uid " + std::to_string(me)));
    if (me == 0) {
        const auto theirs = dir.path() / "finsd-theirs";
        ASSERT_EQ(::mkdir(theirs.c_str(), 0700), 0);
        ASSERT_EQ(::chown(theirs.c_str(), 65534, 65534), 0);
        EXPECT_TRUE(
            has(finsd::prepare_socket_directory(theirs, 0700, 0), "is owned by uid 65534, not 0"));
    }
}

// A stand-in control channel: accepts one client, returns its request line, answers.
class FakeChannel {
  public:
    explicit FakeChannel(std::string path) : path_(std::move(path)) {
        fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::strncpy(a.sun_path, path_.c_str(), sizeof a.sun_path - 1);
        ::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a);
        ::listen(fd_, 4);
    }
    ~FakeChannel() { ::close(fd_); }
    std::string serve_one(const std::string& answer) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 10'000) <= 0) return "";
        const int c = ::accept(fd_, nullptr, nullptr);
        if (c < 0) return "";
        set_receive_timeout(c, 10);
        std::string line;
        char ch = 0;
        while (line.size() < 65536 && ::recv(c, &ch, 1, 0) == 1 && ch != '\n')
            line += ch;
        ::send(c, answer.data(), answer.size(), MSG_NOSIGNAL);
        ::close(c);
        return line;
    }

  private:
    std::string path_;
    int fd_ = -1;
};

// Newcomer 12: `finsd ctl --timeout 5` meant 0.5 s while `fins --timeout 5` means 5 s.
// Both are seconds now, decimals allowed; the control protocol keeps W596's 0.1 s.
TEST(FinsdCtl, Newcomer12_TimeoutIsSecondsAsInFins) {
    ScratchDir dir("ctltimeout");
    const std::string socket = (dir.path() / "fake.sock").string();
    FakeChannel channel(socket);
    const std::string done =
        R"({"ok":true,"result":{"instruction":"send","done":true,"error_id":"0000",)"
        R"("error_id_ex":"0000","end_code":"0000","port":0,"transmissions":1,"detail":""}})"
        "\n";
    for (const auto& [given, tenths] :
         std::vector<std::pair<std::string, int>>{{"5", 50}, {"0.5", 5}, {"2.3", 23}}) {
        Child c({finsd_path, "ctl", "--socket", socket, "send", "--dest", "0.5.0", "--local", "D0",
                 "--remote", "D0", "--timeout", given});
        const Json request = Json::parse(channel.serve_one(done), nullptr, false);
        EXPECT_EQ(request["timeout"], tenths) << given;
        EXPECT_EQ(c.wait().exit_code, 0) << given;
    }
    const auto tiny = run({finsd_path, "ctl", "--socket", socket, "send", "--dest", "0.5.0",
                           "--local", "D0", "--remote", "D0", "--timeout", "0.01"});
    EXPECT_EQ(tiny.exit_code, 2);
    EXPECT_TRUE(has(tiny.err, "at least 0.1 s")) << tiny.err;
}

}  // namespace
}  // namespace fins::test
