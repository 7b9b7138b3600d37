// [http] and the --http flags (contract in config_http.hpp).
#include "finsd/config_http.hpp"

#include "transport/socket_headers.hpp"

#include <charconv>
#include <vector>

#include "config/schema.hpp"

#include <fmt/core.h>
#include <toml++/toml.h>

namespace fins::finsd {

namespace {

using Fail = tl::unexpected<std::string>;

}  // namespace

tl::expected<std::pair<std::string, std::uint16_t>, std::string> parse_http_listen(
    std::string_view text) {
    const auto bad = [&](std::string_view why) {
        return Fail(fmt::format("--http {}: {} (ADDRESS:PORT, e.g. 127.0.0.1:8080 or [::1]:8080)",
                                text, why));
    };
    std::string_view address;
    std::string_view port;
    if (!text.empty() && text.front() == '[') {
        const auto end = text.find("]:");
        if (end == std::string_view::npos) return bad("no port");
        address = text.substr(1, end - 1);
        port = text.substr(end + 2);
    } else {
        const auto colon = text.rfind(':');
        if (colon == std::string_view::npos) return bad("no port");
        address = text.substr(0, colon);
        port = text.substr(colon + 1);
    }
    const std::string a(address);
    unsigned char buffer[16];
    if (::inet_pton(AF_INET, a.c_str(), buffer) != 1 &&
        ::inet_pton(AF_INET6, a.c_str(), buffer) != 1)
        return bad(fmt::format("'{}' is not an IPv4 or IPv6 address", address));
    unsigned value = 0;
    const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
    if (port.empty() || ec != std::errc{} || end != port.data() + port.size() || value > 65535)
        return bad(fmt::format("'{}' is not a port 0-65535", port));
    return std::pair{a, static_cast<std::uint16_t>(value)};
}

bool loopback_address(std::string_view address) {
    const std::string a(address);
    unsigned char b[16];
    if (::inet_pton(AF_INET, a.c_str(), b) == 1) return b[0] == 127;
    return a == "::1";
}

tl::expected<void, std::string> load_http_table(const toml::node& node, std::string_view source,
                                                HttpSettings& http) {
    const auto* table = node.as_table();
    if (table == nullptr) return Fail(fmt::format("{}: http: must be a table", source));
    using config::Entry;
    using config::Type;
    using Done = tl::expected<void, std::string>;
    // A list of strings each `ok` takes, or the complaint `why`.
    const auto list = [](std::string_view name, std::string_view why, auto ok,
                         std::vector<std::string>& out) -> config::Key {
        return {name, Type::any, [why, ok, &out](const Entry& e) -> Done {
                    const auto* a = e.node.as_array();
                    if (a == nullptr) return e.fail(why);
                    out.clear();
                    for (const auto& item : *a) {
                        const auto* s = item.as_string();
                        if (s == nullptr || !ok(s->get())) return e.fail(why);
                        out.push_back(s->get());
                    }
                    return {};
                }};
    };
    // Whole origins, as a browser sends them: scheme://host[:port], no path.
    const auto origin = [](std::string_view v) {
        const auto scheme = v.find("://");
        return scheme != std::string_view::npos && scheme != 0 && v.size() != scheme + 3 &&
               v.find('/', scheme + 3) == std::string_view::npos;
    };
    return config::read_table(
        *table, {source, "http", config::At::key},
        {{"listen", Type::any,
          [&](const Entry& e) -> Done {
              const auto* s = e.node.as_string();
              if (s == nullptr) return e.fail("must be a string ADDRESS:PORT");
              if (auto r = parse_http_listen(s->get()); !r) return e.fail(r.error());
              http.listen = s->get();
              return {};
          }},
         config::flag_key("control", http.control),
         {"token_file", Type::any,
          [&](const Entry& e) -> Done {
              const auto* s = e.node.as_string();
              if (s == nullptr || s->get().empty()) return e.fail("must be a file name");
              http.token_file = s->get();
              return {};
          }},
         list(
             "allowed_hosts", "must be an array of host names",
             [](const std::string& h) { return !h.empty(); }, http.allowed_hosts),
         list("allowed_origins", "must be an array of origins like \"https://scada.lan\"", origin,
              http.allowed_origins),
         {"max_connections", Type::any,
          [&](const Entry& e) -> Done {
              const auto* i = e.node.as_integer();
              if (i == nullptr || i->get() < 1 || i->get() > 1024) return e.fail("must be 1-1024");
              http.max_connections = static_cast<std::size_t>(i->get());
              return {};
          }},
         {"websocket_idle_timeout", Type::any, [&](const Entry& e) -> Done {
              // Seconds, a decimal allowed: 0.2 s (tests) to an hour.
              const auto seconds = e.node.value<double>();
              if (!seconds || !(*seconds >= 0.2 && *seconds <= 3600))
                  return e.fail("must be a number of seconds 0.2-3600");
              http.websocket_idle_timeout = std::chrono::milliseconds(
                  static_cast<std::chrono::milliseconds::rep>(*seconds * 1000 + 0.5));
              return {};
          }}});
}

void add_http_flags(CLI::App& app, HttpFlags& flags) {
    flags.listen_option = app.add_option(
        "--http", flags.listen,
        "Serve the web page, the HTTP/WebSocket API and /metrics on ADDRESS:PORT (docs/web.md)");
    flags.control_option =
        app.add_flag("--http-control", flags.control,
                     "Let HTTP clients write memory and send control requests (default read-only)");
    flags.token_option = app.add_option(
        "--http-token-file", flags.token_file,
        "File holding the bearer token HTTP POSTs must carry (required with --http-control "
        "beyond loopback)");
}

void apply_http_flags(const HttpFlags& flags, HttpSettings& http) {
    if (flags.listen_option != nullptr && flags.listen_option->count() > 0)
        http.listen = flags.listen;
    if (flags.control_option != nullptr && flags.control_option->count() > 0) http.control = true;
    if (flags.token_option != nullptr && flags.token_option->count() > 0)
        http.token_file = flags.token_file;
}

tl::expected<void, std::string> check_http(const HttpSettings& http) {
    if (!http.listen) {
        if (http.control || http.token_file)
            return Fail("--http-control and --http-token-file need --http ADDRESS:PORT");
        return {};
    }
    const auto listen = parse_http_listen(*http.listen);
    if (!listen) return Fail(listen.error());
    if (http.control && !http.token_file && !loopback_address(listen->first))
        return Fail(fmt::format(
            "--http {} is beyond loopback with --http-control: give a bearer token with "
            "--http-token-file FILE (or bind 127.0.0.1)",
            *http.listen));
    return {};
}

}  // namespace fins::finsd
