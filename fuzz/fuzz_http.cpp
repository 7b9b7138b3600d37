// Fuzzes finsd's HTTP and WebSocket message handling (src/web/): the input is split at
// its first 0x00 byte; the part before goes to Beast's request parser with finsd's
// limits, and what parses is checked (web::check_request) and answered
// (web::handle_request) with control on, so writes and control requests reach the
// virtual PLC; the part after is split at 0x0A into WebSocket text messages for one
// client's subscriptions (web::Subscriptions), polled between messages with time moving.
// Every answer must be a status the API documents with a JSON body (or a page file), and
// every WebSocket message JSON: anything else traps.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/string_body.hpp>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "web/api.hpp"
#include "web/subscriptions.hpp"

namespace {

namespace http = boost::beast::http;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

struct State {
    State() {
        fins::server::ControlTarget t;
        t.plc = &plc;
        t.addresses = {{0, 1}};
        context.targets.push_back(t);
        context.options.control = true;
    }
    fins::plc::Plc plc;
    fins::web::WebContext context;
};

void http_request(State& s, std::string_view bytes) {
    http::request_parser<http::string_body> parser;
    parser.body_limit(s.context.options.max_body_bytes);
    parser.header_limit(static_cast<std::uint32_t>(s.context.options.max_header_bytes));
    parser.eager(true);
    boost::beast::error_code ec;
    parser.put(boost::asio::buffer(bytes.data(), bytes.size()), ec);
    if (ec || !parser.is_done()) return;
    const auto& r = parser.get();
    const auto field = [&](http::field f) -> std::optional<std::string_view> {
        const auto it = r.find(f);
        if (it == r.end()) return std::nullopt;
        return std::string_view(it->value().data(), it->value().size());
    };
    fins::web::RequestMeta meta{
        std::string_view(r.method_string().data(), r.method_string().size()),
        std::string_view(r.target().data(), r.target().size()),
        field(http::field::host),
        field(http::field::origin),
        field(http::field::authorization),
        false,
        field(http::field::content_type)};
    if (auto refused = fins::web::check_request(s.context.options, meta)) {
        check(refused->status == 403 || refused->status == 415);
        return;
    }
    int calls = 0;
    fins::web::handle_request(
        s.context, meta.method, meta.target, r.body(), [&](fins::web::HttpAnswer a) {
            ++calls;
            check(a.status == 200 || a.status == 400 || a.status == 403 || a.status == 404 ||
                  a.status == 405);
            if (a.content_type == "application/json")
                check(!nlohmann::json::parse(a.body, nullptr, false).is_discarded());
        });
    // Instruction verbs answer later; this harness has no engine, so every answer is now.
    check(calls == 1);
}

void websocket_messages(State& s, std::string_view bytes) {
    fins::web::Subscriptions subs(s.context, "fuzz");
    auto now = fins::web::SteadyTime{} + std::chrono::hours(1);
    std::vector<std::string> out;
    std::size_t messages = 0;
    while (!bytes.empty() && messages++ < 64) {
        const auto end = bytes.find('\n');
        const auto message = bytes.substr(0, end);
        bytes = end == std::string_view::npos ? std::string_view{} : bytes.substr(end + 1);
        subs.on_message(message, out);
        now += std::chrono::milliseconds(50);
        subs.poll(now, std::chrono::system_clock::now(), out);
    }
    for (const auto& m : out)
        check(!nlohmann::json::parse(m, nullptr, false).is_discarded());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static State state;
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const auto split = input.find('\0');
    http_request(state, input.substr(0, split));
    if (split != std::string_view::npos) websocket_messages(state, input.substr(split + 1));
    return 0;
}
