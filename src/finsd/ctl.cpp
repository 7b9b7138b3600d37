// `finsd ctl [--socket PATH] [--plc NAME|NET.NODE] VERB ...` (options before or after the
// verb): sends one request to a running finsd's control channel (server/control/control.hpp)
// and prints the answer line (Windows: through the channel file's loopback port and token,
// server/control/control_channel_file.hpp). Without --socket: $FINSD_SOCKET, else the first of the
// default places finsd itself uses that holds a socket (control_setup.hpp). --plc picks a CPU Unit
// of a plant (default the first).
//
//   status                          the JSON snapshot
//   battery-error on|off            low battery (error 00F7) / battery replaced
//   fal N [MESSAGE]                 FAL N, N = 1-511, message up to 16 characters
//   fals N [MESSAGE]                FALS N (fatal: the CPU stops)
//   error CODE                      any other W342 5-3-27 error code, hex (0203, 80F0)
//   clear-errors [CODE]             every error (and the battery cause), or one code
//   message N [TEXT]                registers MSG N (0-7); without TEXT unregisters it
//   write-protect on|off            network write protection (PLC Setup, all nodes)
//   um-protect on|off [PASSWORD]    UM read protection; releasing needs the password
//   mode program|monitor|run        operating mode
//   release-access                  drops the access right (as 0C 03)
//   card insert [KB] | card remove  inserts (capacity in KB) or removes the memory card
//   cassette insert | cassette remove  the CP1H Memory Cassette (22 20)
//   send JSON                       any request line as is
//   send|recv|sendcmd|instructions  PLC-initiated messages (ctl_instructions.hpp; their
//                                   own exit codes)
//   scenario status|pause|resume|advance SECONDS|trigger EVENT|reload
//                                   the CPU Unit's scenario (ctl_scenario.hpp)
//   advance SECONDS                 alias of scenario advance SECONDS
//
// Exit codes: 0 the server answered "ok"; 2 usage error or the server refused the
// request (its message on stderr); 3 cannot connect, or no answer within 5 s (an advance
// waits for its answer without a limit: finsd answers when its ticks have run).
#include "finsd/ctl.hpp"
#include "finsd/control_setup.hpp"
#include "finsd/ctl_instructions.hpp"
#include "finsd/ctl_scenario.hpp"

#ifdef _WIN32
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/write.hpp>

#include "server/control/control_channel_file.hpp"
#include "transport/asio.hpp"
#else
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace fins::finsd {

namespace {

constexpr int exit_ok = 0;
constexpr int exit_usage = 2;
constexpr int exit_io = 3;
constexpr int answer_timeout_ms = 5000;
constexpr std::size_t max_answer_size = 1 << 20;

#ifdef _WIN32
// The loopback channel (server/control/control_channel_file.hpp): the port and token read
// from the channel file, a TCP connection to 127.0.0.1, the token line, then the same
// request line as on Linux. The answer is read on an io_context run for at most the wait
// (no bound: until the answer or the end of the connection).
std::optional<std::string> send_request(const std::string& path, const std::string& request,
                                        std::optional<std::chrono::milliseconds> wait) {
    const auto channel = server::read_channel_file(path);
    if (!channel) {
        const auto why = channel.error() == std::make_error_code(std::errc::invalid_argument)
                             ? std::string("not a finsd control channel file")
                             : channel.error().message();
        std::fprintf(stderr, "finsd ctl: cannot connect to %s: %s\n%s\n", path.c_str(), why.c_str(),
                     control_channel_hint().c_str());
        return std::nullopt;
    }
    asio::io_context io;
    asio::ip::tcp::socket s(io);
    boost::system::error_code ec;
    if (s.connect({asio::ip::address_v4::loopback(), channel->port}, ec); ec) {
        std::fprintf(stderr, "finsd ctl: cannot connect to %s (127.0.0.1:%u): %s\n%s\n",
                     path.c_str(), static_cast<unsigned>(channel->port), ec.message().c_str(),
                     control_channel_hint().c_str());
        return std::nullopt;
    }
    if (asio::write(s, asio::buffer(channel->token + "\n" + request + "\n"), ec); ec) {
        std::fprintf(stderr, "finsd ctl: send: %s\n", ec.message().c_str());
        return std::nullopt;
    }
    std::string answer;
    bool done = false;
    asio::async_read_until(s, asio::dynamic_buffer(answer, max_answer_size), '\n',
                           [&](const boost::system::error_code& e, std::size_t n) {
                               done = !e;
                               if (done) answer.resize(n - 1);
                           });
    if (wait)
        io.run_for(std::max(*wait, std::chrono::milliseconds(answer_timeout_ms)));
    else
        io.run();
    if (done) return answer;
    std::fprintf(stderr, "finsd ctl: no answer from %s\n", path.c_str());
    return std::nullopt;
}
#else
struct Fd {
    int fd = -1;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

// Sends `request` (one line) and returns the answer line, or prints why not. `wait`
// (at least answer_timeout_ms) bounds the wait for the answer; nullopt: no bound, until
// the answer comes or finsd closes the connection (a long scenario advance).
std::optional<std::string> send_request(const std::string& path, const std::string& request,
                                        std::optional<std::chrono::milliseconds> wait) {
    sockaddr_un address{};
    if (path.size() >= sizeof address.sun_path) {
        std::fprintf(stderr, "finsd ctl: socket path too long: %s\n", path.c_str());
        return std::nullopt;
    }
    address.sun_family = AF_UNIX;
    std::memcpy(address.sun_path, path.data(), path.size());
    Fd s{::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0)};
    if (s.fd < 0 ||
        ::connect(s.fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
        std::fprintf(stderr, "finsd ctl: cannot connect to %s: %s\n%s\n", path.c_str(),
                     std::strerror(errno), control_channel_hint().c_str());
        return std::nullopt;
    }
    const std::string line = request + "\n";
    for (std::size_t sent = 0; sent < line.size();) {
        const auto n = ::send(s.fd, line.data() + sent, line.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) {
            std::fprintf(stderr, "finsd ctl: send: %s\n", std::strerror(errno));
            return std::nullopt;
        }
        sent += static_cast<std::size_t>(n);
    }
    std::string answer;
    const auto deadline =
        std::chrono::steady_clock::now() + std::max(wait.value_or(std::chrono::milliseconds(0)),
                                                    std::chrono::milliseconds(answer_timeout_ms));
    while (answer.size() < max_answer_size) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        pollfd p{s.fd, POLLIN, 0};
        if (wait && left.count() <= 0) break;
        const int timeout = wait ? static_cast<int>(left.count()) : -1;
        int ready = 0;
        do {
            ready = ::poll(&p, 1, timeout);
        } while (ready < 0 && errno == EINTR && !wait);
        if (ready <= 0) break;
        char buf[4096];
        const auto n = ::recv(s.fd, buf, sizeof buf, 0);
        if (n <= 0) break;
        answer.append(buf, static_cast<std::size_t>(n));
        if (const auto end = answer.find('\n'); end != std::string::npos) {
            answer.resize(end);
            return answer;
        }
    }
    std::fprintf(stderr, "finsd ctl: no answer from %s\n", path.c_str());
    return std::nullopt;
}
#endif

}  // namespace

int run_ctl(int argc, char** argv) {
    using Json = nlohmann::json;
    CLI::App app{"finsd ctl: change a running finsd through its control socket"};
    // Options are --name on Windows too, and an argument such as /path is a value there.
    app.allow_windows_style_options(false);
    app.name("finsd ctl");
    app.require_subcommand(1);
    // Options may follow the verb, as with `fins`: `finsd ctl status --socket PATH`.
    app.fallthrough(true);
    std::string socket;
    app.add_option("--socket", socket,
                   "The control socket (finsd --control PATH; default $FINSD_SOCKET, "
                   "$XDG_RUNTIME_DIR/finsd.sock, /run/finsd/finsd.sock (root) or "
                   "/tmp/finsd-UID/finsd.sock)");
    std::string plc;
    app.add_option("--plc", plc,
                   "The CPU Unit of a plant: its [[plc]] name or FINS address NET.NODE "
                   "(default the first)");

    Json request;
    std::string on_off;
    unsigned number = 0;
    std::string text;
    std::string code;
    std::string mode;
    const auto add_on_off = [&](const char* name, const char* help, const char* cmd) {
        auto* c = app.add_subcommand(name, help);
        c->add_option("state", on_off, "on or off")
            ->required()
            ->check(CLI::IsMember({"on", "off"}));
        c->callback([&, cmd] { request = {{"cmd", cmd}, {"on", on_off == "on"}}; });
    };
    const auto add_fal = [&](const char* name, const char* help) {
        auto* c = app.add_subcommand(name, help);
        c->add_option("number", number, "1-511")->required()->check(CLI::Range(1, 511));
        c->add_option("message", text, "Up to 16 ASCII characters");
        c->callback([&, name] {
            request = {{"cmd", name}, {"number", number}, {"message", text}};
        });
    };

    app.add_subcommand("status", "Print the JSON status snapshot")->callback([&] {
        request = {{"cmd", "status"}};
    });
    add_on_off("battery-error", "Low battery (error 00F7) on, or battery replaced",
               "battery_error");
    add_fal("fal", "Raise FAL N (non-fatal error 4100+N)");
    add_fal("fals", "Raise FALS N (fatal error C100+N: the CPU stops)");
    auto* c_error = app.add_subcommand("error", "Raise another W342 5-3-27 error code");
    c_error->add_option("code", code, "Hex error code, e.g. 0203 or 80F0")->required();
    c_error->callback([&] { request = {{"cmd", "error"}, {"code", code}}; });
    auto* c_clear = app.add_subcommand("clear-errors", "Clear every error, or one code");
    c_clear->add_option("code", code, "Hex error code (default: all)");
    c_clear->callback([&] {
        request = {{"cmd", "clear_errors"}};
        if (!code.empty()) request["code"] = code;
    });
    auto* c_msg = app.add_subcommand("message", "Register MSG N, or unregister it without TEXT");
    c_msg->add_option("number", number, "0-7")->required()->check(CLI::Range(0, 7));
    auto* text_option = c_msg->add_option("text", text, "Up to 32 ASCII characters");
    c_msg->callback([&] {
        request = {{"cmd", "message"}, {"number", number}};
        if (text_option->count() > 0) request["text"] = text;
    });
    add_on_off("write-protect", "Network write protection (all nodes) on or off",
               "network_write_protection");
    std::string password;
    auto* c_um = app.add_subcommand("um-protect", "UM read protection on or off (with PASSWORD)");
    c_um->add_option("state", on_off, "on or off")->required()->check(CLI::IsMember({"on", "off"}));
    c_um->add_option("password", password, "Password: sets it (on) or releases with it (off)");
    c_um->callback([&] {
        request = {{"cmd", "um_read_protection"}, {"on", on_off == "on"}};
        if (!password.empty()) request["password"] = password;
    });
    std::string card_action;
    unsigned card_kbytes = 0;
    auto* c_card = app.add_subcommand("card", "Insert (capacity in KB) or remove the memory card");
    c_card->add_option("action", card_action, "insert or remove")
        ->required()
        ->check(CLI::IsMember({"insert", "remove"}));
    c_card->add_option("kbytes", card_kbytes, "Capacity in KB (insert)")
        ->check(CLI::Range(1U, 4194303U));
    c_card->callback([&] {
        request = {{"cmd", "card"}, {"inserted", card_action == "insert"}};
        if (card_kbytes != 0) request["kbytes"] = card_kbytes;
    });
    std::string cassette_action;
    auto* c_cassette =
        app.add_subcommand("cassette", "Insert or remove the Memory Cassette (CP1H, 22 20)");
    c_cassette->add_option("action", cassette_action, "insert or remove")
        ->required()
        ->check(CLI::IsMember({"insert", "remove"}));
    c_cassette->callback([&] {
        request = {{"cmd", "cassette"}, {"inserted", cassette_action == "insert"}};
    });
    auto* c_mode = app.add_subcommand("mode", "Set the operating mode");
    c_mode->add_option("mode", mode, "program, monitor or run")
        ->required()
        ->check(CLI::IsMember({"program", "monitor", "run"}));
    c_mode->callback([&] { request = {{"cmd", "mode"}, {"mode", mode}}; });
    app.add_subcommand("release-access", "Release the access right (as 0C 03)")->callback([&] {
        request = {{"cmd", "release_access_right"}};
    });
    InstructionVerbs verbs;
    add_instruction_verbs(app, request, verbs);
    add_scenario_verbs(app, request);

    try {
        // argv[0] is "ctl": CLI11 skips it as the program name.
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help
        std::fprintf(stderr, "finsd ctl: %s (see finsd ctl --help)\n", e.what());
        return exit_usage;
    }
    const bool raw_line = verbs.send->parsed() && !verbs.raw.empty();
    if (!plc.empty() && !raw_line) request["plc"] = plc;
    if (socket.empty()) {
        // The first default place that holds a socket (Windows: a channel file), else the
        // first (control_setup.hpp).
        const auto places = default_control_sockets();
        socket = places.front().string();
        for (const auto& place : places) {
            std::error_code ec;
#ifdef _WIN32
            if (std::filesystem::is_regular_file(place, ec)) {
#else
            if (std::filesystem::is_socket(place, ec)) {
#endif
                socket = place.string();
                break;
            }
        }
    }
    // An argument that is not UTF-8 is replaced (U+FFFD), not thrown on.
    const std::string line =
        raw_line ? verbs.raw
                 : request.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (line.find('\n') != std::string::npos) {
        std::fprintf(stderr, "finsd ctl: a request is one line\n");
        return exit_usage;
    }
    // A scenario advance answers when its ticks have run (finsd serves FINS requests
    // meanwhile): a day at 1 ms takes a while, so no fixed limit.
    const bool advance = !raw_line && request.is_object() &&
                         request.value("cmd", "") == "scenario" &&
                         request.value("action", "") == "advance";
    const auto answer =
        send_request(socket, line,
                     advance ? std::nullopt : std::optional<std::chrono::milliseconds>(verbs.wait));
    if (!answer) return exit_io;
    const Json doc = Json::parse(*answer, nullptr, false);
    const bool instruction =
        !raw_line && (verbs.send->parsed() || verbs.recv->parsed() || verbs.sendcmd->parsed());
    if (instruction && doc.is_object()) return print_instruction_answer(doc, *answer, verbs.json);
    std::printf("%s\n", answer->c_str());
    if (doc.is_object() && doc.contains("ok") && doc["ok"] == true) return exit_ok;
    if (doc.is_object() && doc.contains("error") && doc["error"].is_string())
        std::fprintf(stderr, "finsd ctl: %s\n", doc["error"].get<std::string>().c_str());
    return exit_usage;
}

}  // namespace fins::finsd
