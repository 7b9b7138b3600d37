// The files finsd's HTTP server serves from inside its binary: every file of src/web/page/
// (the page), docs/api/openapi.yaml and Debian's libjs-chart.js as chart.js. The table is
// generated at build time by cmake/embed_assets.cmake (no file is read at run time).
#pragma once

#include <span>
#include <string_view>

namespace fins::web {

struct Asset {
    std::string_view name;  // "index.html", "app.js", "openapi.yaml", "chart.js"
    std::string_view body;
};

std::span<const Asset> embedded_assets() noexcept;
// nullptr when there is none of that name.
const Asset* find_asset(std::string_view name) noexcept;

}  // namespace fins::web
