// ControlServer: finsd's run-time control channel (contract in control.hpp).
//
// Protocol: one JSON object per line in, one JSON object per line out, in order.
//   {"cmd":"status"}                                -> {"ok":true,"status":{...}}
//   {"cmd":"battery_error","on":true}               low battery: error 00F7 (flag 0040)
//   {"cmd":"fal","number":5,"message":"TEXT"}       FAL 5 (non-fatal, code 4105)
//   {"cmd":"fals","number":5,"message":"TEXT"}      FALS 5 (fatal, code C105, CPU stops)
//   {"cmd":"error","code":"0203"}                   any other W342 5-3-27 code (hex text
//                                                   or a number)
//   {"cmd":"clear_errors"}                          every error and the battery cause;
//   {"cmd":"clear_errors","code":"4105"}            or just one code (no mode rules)
//   {"cmd":"message","number":3,"text":"TEXT"}      registers MSG 3; no "text" (or
//                                                   null) unregisters it
//   {"cmd":"network_write_protection","on":true}    PLC Setup write protection (all nodes)
//   {"cmd":"um_read_protection","on":false,"password":"..."}  UM read protection
//   {"cmd":"mode","mode":"program"}                 program, monitor or run
//   {"cmd":"release_access_right"}                  as 0C 03 from any node
//   {"cmd":"card","inserted":true,"kbytes":30720}   inserts (capacity in KB, default the
//                                                   profile's or 30720) or removes the card
//   {"cmd":"cassette","inserted":false}             removes (or mounts) the CP1H Memory
//                                                   Cassette; other profiles: an error
//   {"cmd":"send"|"recv"|"sendcmd"|"instructions", ...}  PLC-initiated messages
//                                                   (control_instructions.hpp); these
//                                                   answer when the instruction completes
// Anything else answers {"error":"..."} and the connection stays open. A line longer
// than max_line_size answers an error and closes the connection; at most
// max_connections clients at once (others get an error and are closed). Every handler
// runs on the server's io_context, so the Plc is touched by one thread only.
#include "server/control/control.hpp"

#include <sys/stat.h>

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>
#include <asio/local/stream_protocol.hpp>
#include <asio/read_until.hpp>
#include <asio/streambuf.hpp>
#include <asio/write.hpp>
#include <nlohmann/json.hpp>

#include "fins/commands/diagnostics.hpp"
#include "plc/plc.hpp"
#include "server/control/control_instructions.hpp"

namespace fins::server {

namespace {

using Json = nlohmann::json;
using stream = asio::local::stream_protocol;

// A SendCmd of 2,002 bytes is 4,004 hex digits plus its keys: room for it.
constexpr std::size_t max_line_size = 8192;
constexpr std::size_t max_connections = 16;

std::string hex4(std::uint16_t v) {
    return fmt::format("{:04X}", v);
}

Json fail(const std::string& message) {
    return Json{{"error", message}};
}

const char* mode_name(plc::OperatingMode m) {
    switch (m) {
        case plc::OperatingMode::program:
            return "program";
        case plc::OperatingMode::monitor:
            return "monitor";
        case plc::OperatingMode::run:
            return "run";
    }
    return "run";
}

std::optional<bool> flag(const Json& j, const char* key) {
    auto it = j.find(key);
    if (it == j.end() || !it->is_boolean()) return std::nullopt;
    return it->get<bool>();
}

std::optional<std::uint64_t> number(const Json& j, const char* key) {
    auto it = j.find(key);
    if (it == j.end() || !it->is_number_integer() || it->get<std::int64_t>() < 0)
        return std::nullopt;
    return it->get<std::uint64_t>();
}

// An error code as a number or as hex text ("00F7", "0x00F7").
std::optional<std::uint16_t> error_code(const Json& j) {
    auto it = j.find("code");
    if (it == j.end()) return std::nullopt;
    if (it->is_number_integer()) {
        const auto v = it->get<std::int64_t>();
        if (v < 0 || v > 0xFFFF) return std::nullopt;
        return static_cast<std::uint16_t>(v);
    }
    if (!it->is_string()) return std::nullopt;
    std::string text = it->get<std::string>();
    if (text.rfind("0x", 0) == 0 || text.rfind("0X", 0) == 0) text = text.substr(2);
    if (text.empty() || text.size() > 4) return std::nullopt;
    unsigned v = 0;
    for (char c : text) {
        const int d = (c >= '0' && c <= '9')   ? c - '0'
                      : (c >= 'A' && c <= 'F') ? c - 'A' + 10
                      : (c >= 'a' && c <= 'f') ? c - 'a' + 10
                                               : -1;
        if (d < 0) return std::nullopt;
        v = v * 16 + static_cast<unsigned>(d);
    }
    return static_cast<std::uint16_t>(v);
}

// A text field: absent -> "" (allowed), wrong type, too long or not ASCII -> nullopt.
std::optional<std::string> ascii_text(const Json& j, const char* key, std::size_t max) {
    auto it = j.find(key);
    if (it == j.end() || it->is_null()) return std::string{};
    if (!it->is_string()) return std::nullopt;
    std::string s = it->get<std::string>();
    if (s.size() > max) return std::nullopt;
    for (char c : s)
        if (static_cast<unsigned char>(c) >= 0x80) return std::nullopt;
    return s;
}

Json status(plc::Plc& plc) {
    const auto& errors = plc.errors();
    Json list = Json::array();
    const plc::ActiveError* worst = errors.most_serious();
    for (const auto& e : errors.active()) {
        const auto* info = plc::find_error_code(e.code);
        list.push_back({{"code", hex4(e.code)},
                        {"name", info ? std::string(info->name) : "unknown"},
                        {"fatal", info != nullptr && info->fatal},
                        {"message", std::string(e.text())}});
    }
    Json messages = Json::object();
    for (std::size_t n = 0; n < plc::Messages::count; ++n)
        if (plc.messages().registered(n))
            messages[std::to_string(n)] = std::string(plc.messages().text(n));
    Json holder = nullptr;
    if (const auto& h = plc.access_right_holder())
        holder = fmt::format("{}.{}.{}", h->network, h->node, h->unit);
    return Json{{"model", plc.profile().model},
                {"mode", mode_name(plc.mode())},
                {"running", plc.mode() != plc::OperatingMode::program && !errors.has_fatal()},
                {"end_code_flags", hex4(errors.end_code_flags())},
                {"fatal_errors", hex4(errors.fatal_word())},
                {"non_fatal_errors", hex4(errors.non_fatal_word())},
                {"error_code", hex4(worst != nullptr ? worst->code : 0)},
                {"errors", list},
                {"battery_low", errors.battery_low()},
                {"messages", messages},
                {"error_log_records", errors.log_size()},
                {"write_access_log_records", plc.write_access_log().size()},
                {"access_right_holder", holder},
                {"network_write_protection", plc.network_write_protection()},
                {"um_read_protection", plc.um_read_protection()},
                {"memory_card_kbytes", plc.files().card_kbytes()},
                {"memory_cassette", plc.files().cassette_mounted()}};
}

Json raise_fal(plc::Plc& plc, const Json& j, bool fals, plc::ErrorState::TimePoint now) {
    const auto n = number(j, "number");
    if (!n || *n == 0 || *n > max_fal_number) return fail("\"number\" must be 1-511");
    const auto message = ascii_text(j, "message", error_message_size);
    if (!message) return fail("\"message\" must be ASCII text of at most 16 characters");
    const auto number16 = static_cast<std::uint16_t>(*n);
    const bool ok = fals ? plc.errors().raise_fals(number16, *message, now)
                         : plc.errors().raise_fal(number16, *message, now);
    if (!ok) return fail("too many errors present");
    return Json{{"ok", true}};
}

Json handle(plc::Plc& plc, const Json& j) {
    const auto now = std::chrono::system_clock::now();
    auto& errors = plc.errors();
    const std::string cmd = j.at("cmd").get<std::string>();
    if (cmd == "status") return Json{{"ok", true}, {"status", status(plc)}};
    if (cmd == "battery_error") {
        const auto on = flag(j, "on");
        if (!on) return fail("\"on\" must be true or false");
        errors.set_battery_low(*on, now);
    } else if (cmd == "fal" || cmd == "fals") {
        return raise_fal(plc, j, cmd == "fals", now);
    } else if (cmd == "error") {
        const auto code = error_code(j);
        const auto* info = code ? plc::find_error_code(*code) : nullptr;
        if (info == nullptr) return fail("\"code\" must be an error code of W342 5-3-27");
        if ((*code >= 0x4101 && *code <= 0x42FF) || (*code >= 0xC101 && *code <= 0xC2FF))
            return fail("use \"fal\" / \"fals\" for FAL and FALS errors");
        if (!errors.raise(*code, now)) return fail("too many errors present");
    } else if (cmd == "clear_errors") {
        if (j.contains("code")) {
            const auto code = error_code(j);
            if (!code) return fail("\"code\" must be a hex error code");
            if (*code == plc::battery_error_code) errors.set_battery_low(false, now);
            errors.clear(*code, now);
        } else {
            errors.set_battery_low(false, now);
            errors.clear_all(now);
        }
    } else if (cmd == "message") {
        const auto n = number(j, "number");
        if (!n || *n >= plc::Messages::count) return fail("\"number\" must be 0-7");
        auto it = j.find("text");
        if (it == j.end() || it->is_null()) {
            plc.messages().clear(static_cast<std::uint8_t>(1U << *n));
        } else {
            const auto text = ascii_text(j, "text", msg_text_size);
            if (!text) return fail("\"text\" must be ASCII text of at most 32 characters");
            plc.messages().set(*n, *text);
        }
    } else if (cmd == "network_write_protection") {
        const auto on = flag(j, "on");
        if (!on) return fail("\"on\" must be true or false");
        plc.set_network_write_protection(*on);
    } else if (cmd == "um_read_protection") {
        // What a Programming Device does: protecting may set a password; releasing a
        // password-protected UM needs it (W342 5-1-3 2602 "incorrect password").
        const auto on = flag(j, "on");
        if (!on) return fail("\"on\" must be true or false");
        const auto it = j.find("password");
        const std::string given = it != j.end() && it->is_string() ? it->get<std::string>() : "";
        if (*on) {
            if (!given.empty()) plc.set_um_password(given);
        } else if (!plc.um_password().empty() && given != plc.um_password()) {
            return fail("incorrect password");
        }
        plc.set_um_read_protection(*on);
    } else if (cmd == "mode") {
        const auto it = j.find("mode");
        const std::string m = it != j.end() && it->is_string() ? it->get<std::string>() : "";
        if (m == "program")
            plc.change_mode(plc::OperatingMode::program, std::chrono::system_clock::now());
        else if (m == "monitor")
            plc.change_mode(plc::OperatingMode::monitor, std::chrono::system_clock::now());
        else if (m == "run")
            plc.change_mode(plc::OperatingMode::run, std::chrono::system_clock::now());
        else
            return fail("\"mode\" must be program, monitor or run");
    } else if (cmd == "release_access_right") {
        plc.set_access_right_holder(std::nullopt);
    } else if (cmd == "card") {
        // Memory card (22 xx disk 8000): the files stay on the host while it is out.
        const auto on = flag(j, "inserted");
        if (!on) return fail("\"inserted\" must be true or false");
        if (!*on) {
            plc.files().remove_card();
        } else {
            const std::uint32_t profile_kb = plc.profile().memory_card_kbytes;
            std::uint32_t kbytes = profile_kb != 0 ? profile_kb : 30720U;
            if (j.contains("kbytes")) {
                const auto kb = number(j, "kbytes");
                if (!kb || *kb == 0 || *kb > 4194303) return fail("\"kbytes\" must be 1-4194303");
                kbytes = static_cast<std::uint32_t>(*kb);
            }
            plc.files().insert_card(kbytes);
        }
    } else if (cmd == "cassette") {
        // CP1H Memory Cassette (22 20 disk 8003): its files stay on the host while it is out.
        const auto on = flag(j, "inserted");
        if (!on) return fail("\"inserted\" must be true or false");
        if (!plc.profile().memory_cassette)
            return fail("the " + plc.profile().name + " has no Memory Cassette slot");
        plc.files().mount_cassette(*on);
    } else {
        return fail("unknown cmd \"" + cmd + "\"");
    }
    return Json{{"ok", true}};
}

// One request line -> one answer line (with its newline). Never throws.
std::string answer(plc::Plc& plc, const std::string& line) {
    Json reply;
    try {
        const Json j = Json::parse(line, nullptr, false);
        if (j.is_discarded())
            reply = fail("not JSON");
        else if (!j.is_object() || !j.contains("cmd") || !j["cmd"].is_string())
            reply = fail("expected an object with a string \"cmd\"");
        else
            reply = handle(plc, j);
    } catch (const std::exception& e) {
        reply = fail(std::string("bad request: ") + e.what());
    }
    return reply.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}

struct Shared {
    plc::Plc* plc = nullptr;
    NetworkInstructions* instructions = nullptr;
    const InstructionSchedule* schedule = nullptr;
    bool stopped = false;
};

class Session : public std::enable_shared_from_this<Session> {
  public:
    Session(stream::socket socket, std::shared_ptr<Shared> shared)
        : socket_(std::move(socket)), buffer_(max_line_size), shared_(std::move(shared)) {}

    void start() { read(); }
    void close() {
        std::error_code ignored;
        socket_.close(ignored);
    }
    // Sends one line and closes (refusals before any request is read).
    void refuse(const std::string& message) {
        reply_ = fail(message).dump() + "\n";
        write(true);
    }

  private:
    void read() {
        asio::async_read_until(socket_, buffer_, '\n',
                               [self = shared_from_this()](std::error_code ec, std::size_t n) {
                                   self->on_line(ec, n);
                               });
    }

    void on_line(std::error_code ec, std::size_t n) {
        if (shared_->stopped) return;
        if (ec == asio::error::not_found) {  // the buffer is full and holds no newline
            reply_ =
                fail(fmt::format("request line longer than {} bytes", max_line_size)).dump() + "\n";
            return write(true);
        }
        if (ec) return close();
        const auto data = buffer_.data();
        std::string line(asio::buffers_begin(data),
                         asio::buffers_begin(data) + static_cast<std::ptrdiff_t>(n - 1));
        buffer_.consume(n);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (instruction(line)) return;
        reply_ = answer(*shared_->plc, line);
        write(false);
    }

    // A send / recv / sendcmd line: the answer is written when the instruction ends
    // (the next line is read only then, so answers stay in request order).
    bool instruction(const std::string& line) {
        const Json j = Json::parse(line, nullptr, false);
        if (j.is_discarded() || !j.is_object() || !j.contains("cmd") || !j["cmd"].is_string())
            return false;
        return handle_instruction_request(
            shared_->instructions, shared_->schedule, j, [self = shared_from_this()](Json reply) {
                if (self->shared_->stopped) return;
                self->reply_ = reply.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
                self->write(false);
            });
    }

    void write(bool close_after) {
        asio::async_write(
            socket_, asio::buffer(reply_),
            [self = shared_from_this(), close_after](std::error_code ec, std::size_t) {
                if (ec || close_after || self->shared_->stopped) return self->close();
                self->read();
            });
    }

    stream::socket socket_;
    asio::streambuf buffer_;
    std::shared_ptr<Shared> shared_;
    std::string reply_;
};

}  // namespace

struct ControlServer::Impl {
    Impl(asio::io_context& io, std::filesystem::path p) : acceptor(io), path(std::move(p)) {}

    void accept() {
        acceptor.async_accept([this, shared = shared](std::error_code ec, stream::socket socket) {
            if (shared->stopped || ec == asio::error::operation_aborted) return;
            if (!ec) {
                std::erase_if(sessions, [](const auto& w) { return w.expired(); });
                auto session = std::make_shared<Session>(std::move(socket), shared);
                if (sessions.size() >= max_connections) {
                    session->refuse("too many control connections");
                } else {
                    sessions.push_back(session);
                    session->start();
                }
            }
            accept();
        });
    }

    stream::acceptor acceptor;
    std::filesystem::path path;
    std::shared_ptr<Shared> shared = std::make_shared<Shared>();
    std::vector<std::weak_ptr<Session>> sessions;
};

Result<std::unique_ptr<ControlServer>> ControlServer::start(asio::io_context& io, plc::Plc& plc,
                                                            const std::filesystem::path& path,
                                                            NetworkInstructions* instructions,
                                                            const InstructionSchedule* schedule) {
    // sockaddr_un holds at most 107 characters and a terminating NUL.
    if (path.empty() || path.native().size() >= sizeof(sockaddr_un{}.sun_path))
        return Unexpected(std::make_error_code(std::errc::filename_too_long));
    std::error_code ec;
    const auto st = std::filesystem::symlink_status(path, ec);
    if (std::filesystem::exists(st)) {
        // Replace a stale socket, never a regular file someone pointed us at by mistake,
        // nor the socket of a finsd that still answers on it.
        if (!std::filesystem::is_socket(st))
            return Unexpected(std::make_error_code(std::errc::file_exists));
        stream::socket probe(io);
        if (probe.connect(stream::endpoint(path.native()), ec); !ec)
            return Unexpected(std::make_error_code(std::errc::address_in_use));
        std::filesystem::remove(path, ec);
    }
    auto impl = std::make_unique<Impl>(io, path);
    impl->shared->plc = &plc;
    impl->shared->instructions = instructions;
    impl->shared->schedule = schedule;
    const stream::endpoint endpoint(path.native());
    if (impl->acceptor.open(endpoint.protocol(), ec); ec) return Unexpected(ec);
    if (impl->acceptor.bind(endpoint, ec); ec) return Unexpected(ec);
    ::chmod(path.c_str(), 0600);  // the channel changes the PLC: its owner only
    if (impl->acceptor.listen(asio::socket_base::max_listen_connections, ec); ec)
        return Unexpected(ec);
    impl->accept();
    return std::unique_ptr<ControlServer>(new ControlServer(std::move(impl)));
}

ControlServer::ControlServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ControlServer::~ControlServer() {
    stop();
}

void ControlServer::stop() {
    if (!impl_ || impl_->shared->stopped) return;
    impl_->shared->stopped = true;
    std::error_code ec;
    impl_->acceptor.close(ec);
    for (auto& w : impl_->sessions)
        if (auto s = w.lock()) s->close();
    impl_->sessions.clear();
    std::filesystem::remove(impl_->path, ec);
}

}  // namespace fins::server
