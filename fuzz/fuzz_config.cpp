// Fuzzes the TOML configuration loaders and the control channel's file: text a user or a
// careless tool wrote, read by finsd and fins-bridge at start-up, by `finsd ctl`, and by
// finskit.VirtualPlc(scenario=...). Every input must end in a value or an error message,
// never a crash, a hang or an exception out of the loader.
//
// Input: byte 0 picks the reader (modulo 4), the rest is its text:
//   0  finsd's configuration (load_config_text, then validate: docs/finsd.md)
//   1  fins-bridge's configuration (parse_config: docs/bridge.md)
//   2  a [scenario] table (load_scenario_text, then compile_scenario against a PLC)
//   3  the control channel's file `<port> <token>` (parse_channel_file)
// A message must say something: an error is never an empty string.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <spdlog/spdlog.h>

#include "bridge/config.hpp"
#include "finsd/config.hpp"
#include "finsd/config_scenario.hpp"
#include "plc/plc.hpp"
#include "scenario/scenario.hpp"  // compile_scenario returns a unique_ptr to it
#include "server/control/control_channel_file.hpp"

namespace {

void check(bool ok) {
    if (!ok) __builtin_trap();
}

void finsd_config(std::string_view text) {
    fins::finsd::Settings settings;
    auto loaded = fins::finsd::load_config_text(text, "<fuzz>", settings);
    if (!loaded) {
        check(!loaded.error().empty());
        return;
    }
    auto valid = fins::finsd::validate(settings);
    if (!valid) check(!valid.error().empty());
}

void bridge_config(std::string_view text) {
    auto config = fins::bridge::parse_config(std::string(text), "<fuzz>", "fuzz");
    if (!config) check(!config.error().empty());
}

void scenario(std::string_view text) {
    auto loaded = fins::finsd::load_scenario_text(text, "<fuzz>");
    if (!loaded) {
        check(!loaded.error().empty());
        return;
    }
    fins::plc::Plc plc;
    auto compiled = fins::finsd::compile_scenario(*loaded, plc);
    if (!compiled) check(!compiled.error().empty());
}

void channel_file(std::string_view text) {
    const auto channel = fins::server::parse_channel_file(text);
    if (!channel) return;
    check(channel->port != 0);
    check(channel->token.size() >= 16 && channel->token.size() <= 256);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const bool quiet = [] {
        spdlog::set_level(spdlog::level::off);
        return true;
    }();
    (void)quiet;
    if (size == 0) return 0;
    const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
    switch (data[0] % 4) {
        case 0:
            finsd_config(text);
            break;
        case 1:
            bridge_config(text);
            break;
        case 2:
            scenario(text);
            break;
        default:
            channel_file(text);
            break;
    }
    return 0;
}
