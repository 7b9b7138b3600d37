// Send, Rcv and SendCmd parameters: checks and parsers (instruction_parameters.hpp).
#include "server/instructions/instruction_parameters.hpp"

#include <array>
#include <charconv>

#include <fmt/format.h>

namespace fins::server {

namespace {

// W596 eAREA: _CIO _WR _HR _TIMER _COUNTER _DM _EM0.._EM18.
bool remote_area_allowed(const Address& a) noexcept {
    switch (a.area) {
        case Area::cio:
        case Area::work:
        case Area::holding:
        case Area::timer:
        case Area::counter:
        case Area::dm:
            return true;
        case Area::em:
            return a.bank <= 0x18;
        default:
            return false;
    }
}

std::optional<std::uint16_t> number(std::string_view text, unsigned max) noexcept {
    int base = 10;
    if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
        text.remove_prefix(2);
        base = 16;
    }
    unsigned v = 0;
    const auto* end = text.data() + text.size();
    const auto r = std::from_chars(text.data(), end, v, base);
    if (text.empty() || r.ec != std::errc{} || r.ptr != end || v > max) return std::nullopt;
    return static_cast<std::uint16_t>(v);
}

}  // namespace

Result<plc::ElementRange> locate_instruction_words(const plc::IoMemory& memory,
                                                   const InstructionRequest& r) {
    const auto address = to_memory_address(r.local, Access::word);
    if (!address) return Unexpected(address.error());
    const bool recv = r.kind == InstructionKind::recv;
    return memory.locate(*address, r.count, recv ? use_write : use_read,
                         recv ? plc::Intent::write : plc::Intent::read);
}

std::chrono::milliseconds instruction_timeout(std::uint16_t timeout) noexcept {
    return std::chrono::milliseconds(100U * (timeout == 0 ? default_instruction_timeout : timeout));
}

std::optional<InstructionKind> parse_instruction_kind(std::string_view text) noexcept {
    if (text == "send") return InstructionKind::send;
    if (text == "recv" || text == "rcv") return InstructionKind::recv;
    if (text == "sendcmd" || text == "cmnd") return InstructionKind::sendcmd;
    return std::nullopt;
}

const char* instruction_kind_name(InstructionKind kind) noexcept {
    switch (kind) {
        case InstructionKind::send:
            return "send";
        case InstructionKind::recv:
            return "recv";
        case InstructionKind::sendcmd:
            return "sendcmd";
    }
    return "send";
}

std::optional<NodeAddress> parse_destination(std::string_view text) noexcept {
    std::array<std::uint16_t, 3> parts{0, 0, 0};
    std::size_t n = 0;
    while (n < parts.size()) {
        const auto dot = text.find('.');
        const auto part = text.substr(0, dot);
        const auto v = number(part, 255);
        if (!v) return std::nullopt;
        parts[n++] = *v;
        if (dot == std::string_view::npos) break;
        text.remove_prefix(dot + 1);
        if (n == parts.size()) return std::nullopt;
    }
    if (n < 2 || parts[0] > 127) return std::nullopt;
    return NodeAddress{static_cast<std::uint8_t>(parts[0]), static_cast<std::uint8_t>(parts[1]),
                       static_cast<std::uint8_t>(parts[2])};
}

std::optional<std::string> check_instruction(const InstructionRequest& r,
                                             const plc::IoMemory& memory) {
    const auto& o = r.options;
    if (r.destination.network > 127) return "destination network must be 0-127";
    if (o.retries > max_instruction_retries) return "retries must be 0-15";
    const bool broadcast = r.destination.node == broadcast_node;
    if (r.kind == InstructionKind::sendcmd) {
        if (r.command.size() == 1) return "a command needs MRC and SRC (2 bytes at least)";
        if (r.command.size() > max_instruction_command)
            return fmt::format("a command has at most {} bytes", max_instruction_command);
        return std::nullopt;
    }
    if (r.kind == InstructionKind::recv) {
        if (broadcast) return "Rcv cannot broadcast (node 255)";
        if (o.no_response) return "Rcv needs a response (no-response mode is not allowed)";
    }
    if (r.count > max_instruction_words)
        return fmt::format("count must be 0-{} words", max_instruction_words);
    if (r.local.bit || r.remote.bit) return "addresses must be words (no .bit)";
    if (!remote_area_allowed(r.remote))
        return fmt::format("remote area of {} is not CIO, W, H, T, C, D or E0_-E18_ (W596 3)",
                           format_address(r.remote));
    if (r.count > 0 && std::uint32_t{r.remote.word} + r.count - 1 > max_word(r.remote.area))
        return fmt::format("remote words {} + {} run past the area", format_address(r.remote),
                           r.count);
    if (r.count == 0) return std::nullopt;
    const auto local = locate_instruction_words(memory, r);
    if (!local)
        return fmt::format("local words {} x {}: {}", format_address(r.local), r.count,
                           local.error().message());
    if (local->kind != ElementKind::word) return "local address must name words";
    return std::nullopt;
}

}  // namespace fins::server
