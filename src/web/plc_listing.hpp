// GET /api/plcs (docs/web.md "The CPU Units"): the CPU Units served, all of them or a
// page (?offset=&limit=), built a slice at a time on the io_context so that FINS, which
// shares that thread, is served between the slices whatever the size of the plant.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "web/api.hpp"
#include "web/web_context.hpp"

namespace fins::web {

// The units [offset, offset + limit) of context.targets; no limit: to the last one.
struct ListingRange {
    std::size_t offset = 0;
    std::optional<std::size_t> limit;
};

// ?offset= and ?limit= (each absent, or decimal digits alone that fit a std::size_t; an
// offset past the last unit is an empty page); anything else is a 400 answer naming the
// parameter.
std::optional<HttpAnswer> parse_listing_range(const std::string* offset, const std::string* limit,
                                              ListingRange& out);

// One CPU Unit's entry: name, model, profile, addresses, net, node, unit, mode, em_banks,
// areas, routing_tables, routes, relays and what context.describe adds.
nlohmann::json plc_entry(const WebContext& context, const server::ControlTarget& target);

// Answers the listing of `range` through `done`: {"plcs":[...],"total","offset","limit",
// "next","control","token_required"}. With context.executor, the entries are built at
// most options.listing_slice at a time (at least one entry a slice) and the rest is
// posted, so `done` runs later on the io_context; without one, at once.
void list_plcs(WebContext& context, ListingRange range, std::function<void(HttpAnswer)> done);

}  // namespace fins::web
