// GET /api/plcs (contract in plc_listing.hpp).
#include "web/plc_listing.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <exception>
#include <memory>
#include <utility>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/control/control_requests.hpp"
#include "web/cpu_facts.hpp"

namespace fins::web {

namespace {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// Decimal digits only, as a std::size_t.
std::optional<std::size_t> count_param(const std::string& text) {
    if (text.empty()) return std::nullopt;
    std::size_t n = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), n);
    if (r.ec != std::errc{} || r.ptr != text.data() + text.size()) return std::nullopt;
    return n;
}

std::string dumped(const Json& j) {
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

// One request's listing under way: the entries [next, end) still to build into `body`.
class Listing : public std::enable_shared_from_this<Listing> {
  public:
    Listing(WebContext& context, std::size_t offset, std::size_t end,
            std::optional<std::size_t> limit, std::function<void(HttpAnswer)> done)
        : context_(context),
          offset_(offset),
          next_(offset),
          end_(end),
          limit_(limit),
          done_(std::move(done)) {
        body_ = "{\"plcs\":[";
    }

    // Builds a slice (everything without an executor); posts the rest.
    void step() {
        const auto deadline = Clock::now() + context_.options.listing_slice;
        const bool sliced = static_cast<bool>(context_.executor);
        while (next_ < end_) {
            if (next_ != offset_) body_ += ',';
            body_ += dumped(plc_entry(context_, context_.targets[next_]));
            // Room for the rest at the first entry's size and a margin: no copy of the
            // whole body each time it doubles (at 10,000 units, a few ms of one slice).
            if (next_ == offset_) body_.reserve(body_.size() * (end_ - offset_) * 5 / 4 + 256);
            ++next_;
            if (sliced && next_ < end_ && Clock::now() >= deadline) {
                boost::asio::post(context_.executor, [self = shared_from_this()] {
                    // Outside the session's failure boundary: an exception ends this
                    // request with a 500, never io_context::run.
                    try {
                        self->step();
                    } catch (const std::exception& e) {
                        self->fail(e.what());
                    } catch (...) {
                        self->fail("unknown exception");
                    }
                });
                return;
            }
        }
        finish();
    }

    void fail(std::string_view what) {
        spdlog::error("web: GET /api/plcs failed: {} (answered 500, the server goes on)", what);
        done_(error_answer(500, "internal error: see finsd's log"));
    }

  private:
    void finish() {
        const std::size_t total = context_.targets.size();
        // token_required: POSTs need --http-token-file's token (the page asks for it).
        const Json tail{{"total", total},
                        {"offset", offset_},
                        {"limit", limit_ ? Json(*limit_) : Json(nullptr)},
                        {"next", end_ < total ? Json(end_) : Json(nullptr)},
                        {"control", context_.options.control},
                        {"token_required", !context_.options.token.empty()}};
        const std::string rest = dumped(tail);  // {"control":...}
        body_ += "],";
        body_.append(rest, 1, std::string::npos);
        done_(HttpAnswer{200, "application/json", std::move(body_)});
    }

    WebContext& context_;
    std::size_t offset_;
    std::size_t next_;
    std::size_t end_;
    std::optional<std::size_t> limit_;
    std::function<void(HttpAnswer)> done_;
    std::string body_;
};

}  // namespace

std::optional<HttpAnswer> parse_listing_range(const std::string* offset, const std::string* limit,
                                              ListingRange& out) {
    out = {};
    if (offset != nullptr) {
        const auto n = count_param(*offset);
        if (!n)
            return error_answer(
                400, fmt::format("offset={}: not a number of units (0 or more)", *offset));
        out.offset = *n;
    }
    if (limit != nullptr) {
        const auto n = count_param(*limit);
        if (!n)
            return error_answer(400,
                                fmt::format("limit={}: not a number of units (0 or more)", *limit));
        out.limit = *n;
    }
    return std::nullopt;
}

Json plc_entry(const WebContext& context, const server::ControlTarget& t) {
    Json addresses = Json::array();
    for (const auto& [net, node] : t.addresses)
        addresses.push_back(fmt::format("{}.{}", net, node));
    Json entry{{"name", t.name},
               {"model", t.plc->profile().model},
               {"profile", t.plc->profile().name},
               {"addresses", addresses},
               {"net", t.addresses.empty() ? 0 : t.addresses.front().first},
               {"node", t.addresses.empty() ? 0 : t.addresses.front().second},
               {"unit", 0},
               {"mode", server::mode_name(t.plc->mode())},
               {"em_banks", t.plc->profile().em_banks},
               {"areas", memory_areas(t.plc->profile())}};
    // The CPU Unit's routing tables (parameter area 8013, W342 5-3-8): what the router uses.
    const auto decoded =
        plc::decode_routing_tables(t.plc->parameters().words(plc::routing_table_area));
    Json routes = Json::array();
    if (decoded.state == plc::RoutingTablesState::valid) {
        const auto& tables = decoded.tables;
        for (std::size_t i = 0; i < tables.local_count; ++i)
            routes.push_back({{"network", tables.local[i].network},
                              {"local", true},
                              {"unit", tables.local[i].unit}});
        for (std::size_t i = 0; i < tables.relay_count; ++i)
            routes.push_back({{"network", tables.relay[i].network},
                              {"local", false},
                              {"relay_network", tables.relay[i].relay_network},
                              {"relay_node", tables.relay[i].relay_node}});
    }
    entry["routing_tables"] = decoded.state == plc::RoutingTablesState::valid  ? "valid"
                              : decoded.state == plc::RoutingTablesState::none ? "none"
                                                                               : "broken";
    entry["routes"] = std::move(routes);
    entry["relays"] = Json::object();
    if (context.describe) context.describe(t, entry);
    return entry;
}

void list_plcs(WebContext& context, ListingRange range, std::function<void(HttpAnswer)> done) {
    const std::size_t total = context.targets.size();
    const std::size_t offset = std::min(range.offset, total);
    const std::size_t end = range.limit ? offset + std::min(*range.limit, total - offset) : total;
    std::make_shared<Listing>(context, offset, end, range.limit, std::move(done))->step();
}

}  // namespace fins::web
