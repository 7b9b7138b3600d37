// finsd settings after the file: command-line overrides, cross-field validation, and
// the [memory] initial values (config.hpp).
#include <algorithm>
#include <charconv>
#include <chrono>

#include <fmt/format.h>

#include "finsd/config.hpp"
#include "plc/profile.hpp"

namespace fins::finsd {

namespace {

tl::unexpected<Error> error(std::string message) {
    return tl::unexpected<Error>(std::move(message));
}

bool number(std::string_view text, unsigned& out) noexcept {
    if (text.empty()) return false;
    const auto* end = text.data() + text.size();
    const auto [p, ec] = std::from_chars(text.data(), end, out);
    return ec == std::errc{} && p == end;
}

std::string known_profiles() {
    std::string names;
    for (const auto& p : plc::profiles())
        names += (names.empty() ? "" : ", ") + p.name;
    return names;
}

constexpr std::uint32_t bits_per_word = 16;

// Words [first, end) of the region an entry touches.
plc::WordRange span_of(const MemoryInit& e) noexcept {
    const auto count = static_cast<std::uint32_t>(e.values.size());
    if (!e.address.bit) return {e.address.word, e.address.word + count};
    const std::uint32_t last_bit = *e.address.bit + count - 1;
    return {e.address.word, e.address.word + last_bit / bits_per_word + 1};
}

}  // namespace

std::optional<plc::OperatingMode> parse_mode(std::string_view text) noexcept {
    if (text == "program" || text == "stop") return plc::OperatingMode::program;
    if (text == "monitor") return plc::OperatingMode::monitor;
    if (text == "run") return plc::OperatingMode::run;
    return std::nullopt;
}

std::optional<plc::NetworkWriteProtection> parse_protection(std::string_view text) noexcept {
    using P = plc::NetworkWriteProtection;
    if (text == "off") return P::off;
    if (text == "all") return P::all;
    if (text == "listed") return P::listed;
    if (text == "all-except-listed") return P::all_except_listed;
    return std::nullopt;
}

std::optional<plc::Durability> parse_durability(std::string_view text) noexcept {
    if (text == "process") return plc::Durability::process;
    if (text == "power") return plc::Durability::power;
    return std::nullopt;
}

std::optional<NodeAddress> parse_node(std::string_view text) noexcept {
    const auto dot = text.find('.');
    if (dot == std::string_view::npos) return std::nullopt;
    unsigned network = 0;
    unsigned node = 0;
    if (!number(text.substr(0, dot), network) || network > 127) return std::nullopt;
    const auto node_text = text.substr(dot + 1);
    if (node_text == "*")
        node = plc::any_node;
    else if (!number(node_text, node) || node < 1 || node > 254)
        return std::nullopt;
    return NodeAddress{static_cast<std::uint8_t>(network), static_cast<std::uint8_t>(node), 0};
}

Expected<void> apply_overrides(const Overrides& o, Settings& s) {
    if (auto r = apply_serial_flags(o.serial, s.serial); !r) return r;
    if (o.profile) s.profile = *o.profile;
    if (o.mode) {
        const auto m = parse_mode(*o.mode);
        if (!m) return error(fmt::format("--mode: '{}' is not program, monitor or run", *o.mode));
        s.mode = *m;
    }
    if (o.data_dir) s.data_dir = *o.data_dir;
    if (o.control_socket) s.control_socket = *o.control_socket;
    if (o.log_level) s.log_level = *o.log_level;
    if (o.bind) s.bind = *o.bind;
    if (o.port) s.port = *o.port;
    if (o.node) {
        if (*o.node < 1 || *o.node > 254)
            return error(fmt::format("--node: {} is not 1-254", *o.node));
        s.node = static_cast<std::uint8_t>(*o.node);
    }
    if (o.network) {
        if (*o.network > 127) return error(fmt::format("--network: {} is not 0-127", *o.network));
        s.network = static_cast<std::uint8_t>(*o.network);
    }
    if (o.udp) s.udp = *o.udp;
    if (o.tcp) s.tcp = *o.tcp;
    if (o.max_connections) s.max_connections = *o.max_connections;
    if (o.tcp_handshake_timeout) s.tcp_handshake_timeout = *o.tcp_handshake_timeout;
    if (o.tcp_frame_timeout) s.tcp_frame_timeout = *o.tcp_frame_timeout;
    if (o.tcp_idle_timeout) s.tcp_idle_timeout = *o.tcp_idle_timeout;
    if (o.tcp_keepalive) s.tcp_keepalive = *o.tcp_keepalive;
    if (o.tcp_max_pending) s.tcp_max_pending = *o.tcp_max_pending;
    if (o.network_write_protection) {
        const auto m = parse_protection(*o.network_write_protection);
        if (!m)
            return error(fmt::format(
                "--network-write-protection: '{}' is not off, all, listed or all-except-listed",
                *o.network_write_protection));
        s.network_write_protection.mode = *m;
    }
    if (!o.protect_nodes.empty()) {
        if (o.protect_nodes.size() > plc::max_protection_nodes)
            return error(
                fmt::format("--protect-node: more than {} nodes", plc::max_protection_nodes));
        s.network_write_protection.nodes.clear();
        for (const auto& text : o.protect_nodes) {
            const auto n = parse_node(text);
            if (!n)
                return error(
                    fmt::format("--protect-node: '{}' is not network.node (network "
                                "0-127, node 1-254 or *)",
                                text));
            s.network_write_protection.nodes.push_back(*n);
        }
    }
    if (o.um_read_protection) s.um_read_protection = *o.um_read_protection;
    if (o.dip_write_protection) s.dip_write_protection = *o.dip_write_protection;
    if (o.durability) {
        const auto d = parse_durability(*o.durability);
        if (!d)
            return error(fmt::format("--durability: '{}' is not process or power", *o.durability));
        s.durability = *d;
    }
    if (o.reset_state) s.reset_state = true;
    return {};
}

Expected<void> validate(const Settings& s) {
    if (plc::find_profile(s.profile) == nullptr)
        return error(fmt::format("profile: unknown '{}' (known: {})", s.profile, known_profiles()));
    // A Host Link port answers FINS by itself: a serial-only PLC is a real set-up.
    const bool host_link =
        std::any_of(s.serial.begin(), s.serial.end(),
                    [](const SerialPortConfig& p) { return p.mode == "hostlink"; });
    if (!s.udp && !s.tcp && !host_link)
        return error(
            "network: udp and tcp are both off and no serial port is in hostlink mode, nothing "
            "to serve");
    if (auto r = validate_serial(s.serial); !r) return r;
    for (const auto& p : s.serial)
        if (p.network && s.network != 0 && *p.network == s.network)
            return error(fmt::format("{}: serial port {}: network={} is this node's own network",
                                     p.where, p.name, *p.network));
    static constexpr std::string_view levels[] = {"trace", "debug", "info", "warn", "error", "off"};
    if (std::find(std::begin(levels), std::end(levels), s.log_level) == std::end(levels))
        return error(fmt::format("log_level: '{}' is not trace, debug, info, warn, error or off",
                                 s.log_level));
    if (s.network_write_protection.mode == plc::NetworkWriteProtection::listed &&
        s.network_write_protection.nodes.empty())
        return error("protection.nodes: empty, so network_write = \"listed\" protects nothing");
    if (const auto e = plc::validate(s.inject); !e.empty()) return error("inject." + e);
    if (s.durability == plc::Durability::power && !s.data_dir)
        return error("storage.durability: \"power\" needs data_dir (without one nothing is kept)");
    return check_file_memory(s, s.profile, "files");
}

Expected<void> check_file_memory(const server::FileMemoryOptions& o, const std::string& profile,
                                 std::string_view path) {
    const auto* model = plc::find_profile(profile);
    if (o.cassette.value_or(false) && !model->memory_cassette)
        return error(
            fmt::format("{}.cassette: the {} has no Memory Cassette slot (22 20 is a CP1H command)",
                        path, profile));
    if (o.em_file_bank && *o.em_file_bank >= model->em_banks)
        return error(fmt::format("{}.em_file_bank: the {} has no EM bank {}", path, profile,
                                 *o.em_file_bank));
    return {};
}

Expected<void> check_initial_memory(const std::vector<MemoryInit>& entries,
                                    const plc::IoMemory& memory) {
    for (const auto& e : entries) {
        const auto address = to_memory_address(e.address);
        if (!address)
            return error(fmt::format("{}: {}: {}", e.where, e.path, address.error().message()));
        const auto count = static_cast<std::uint32_t>(e.values.size());
        const auto range = memory.locate(*address, count, use_write, plc::Intent::write);
        if (!range)
            return error(fmt::format("{}: {}: cannot be written on the {} ({} values): {}", e.where,
                                     e.path, memory.profile().model, count,
                                     range.error().message()));
    }
    return {};
}

bool writes_retained_memory(const MemoryInit& e) noexcept {
    switch (e.address.area) {
        case Area::holding:
        case Area::dm:
        case Area::em:
        case Area::em_current:
        case Area::counter:
            return true;
        case Area::auxiliary: {
            const auto span = span_of(e);
            for (const auto& r : plc::retained_auxiliary_words())
                if (span.first < r.end && r.first < span.end) return true;
            return false;
        }
        default:
            return false;
    }
}

std::size_t apply_initial_memory(const std::vector<MemoryInit>& entries, plc::IoMemory& memory,
                                 bool restored) {
    std::size_t written = 0;
    std::vector<std::uint8_t> data;
    for (const auto& e : entries) {
        if (restored && writes_retained_memory(e)) continue;
        const auto address = to_memory_address(e.address);
        if (!address) continue;
        const auto range = memory.locate(*address, static_cast<std::uint32_t>(e.values.size()),
                                         use_write, plc::Intent::write);
        if (!range) continue;
        const auto size = plc::element_bytes(range->kind);
        data.clear();
        for (const auto v : e.values)
            for (unsigned i = size; i-- > 0;)
                data.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
        if (memory.write(*range, data) == EndCode::normal_completion) ++written;
    }
    return written;
}

void apply_cpu_options(const CpuUnitOptions& options, plc::Plc& plc) {
    plc.set_network_write_protection_setting(options.network_write_protection);
    plc.set_um_read_protection(options.um_read_protection);
    plc.set_um_password(options.um_password);
    plc.set_dip_write_protection(options.dip_write_protection);
    plc::apply(options.inject, plc, std::chrono::system_clock::now());
}

}  // namespace fins::finsd
