// How `fins` reports: results on stdout (text or one JSON document), errors on stderr
// with the "fins:" prefix (and, with --json, {"error": {...}} on stdout), exit codes by
// the kind of failure, CPU error flags of read answers, progress of long transfers.
#include <unistd.h>

#include <cstdio>
#include <string>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "fins/error.hpp"

namespace fins::cli {

namespace {

// What the caller did wrong (exit 2) versus what the PLC said (exit 4) versus what went
// wrong between the two (exit 3). Address and value errors are found before anything is
// sent; invalid_argument is the client refusing a request it cannot encode.
ErrorKind kind_of(std::error_code ec) {
    if (ec.category() == end_code_category()) return ErrorKind::end_code;
    if (ec.category() == address_category()) return ErrorKind::usage;
    if (ec == make_error_code(ClientError::invalid_argument) ||
        ec == make_error_code(ClientError::request_too_long))
        return ErrorKind::usage;
    return ErrorKind::transport;
}

const char* kind_name(ErrorKind k) {
    switch (k) {
        case ErrorKind::usage:
            return "usage";
        case ErrorKind::end_code:
            return "end_code";
        case ErrorKind::transport:
            break;
    }
    return "transport";
}

// One JSON document on a line. Values read from memory are valid UTF-8 (Latin-1 text,
// fins/values.hpp), but a message may quote an argument: replace its invalid bytes
// rather than throw.
std::string dump(const nlohmann::json& j) {
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

std::string plural(std::size_t n, std::string_view one, std::string_view many) {
    return fmt::format("{} {}", n, n == 1 ? one : many);
}
std::string plural(std::size_t n, std::string_view one) {
    return plural(n, one, std::string(one) + "s");
}

std::string node_text(const NodeAddress& a) {
    // Units are hex in the manuals (10-1F CPU Bus Units, E1 Inner Board, FE): print them
    // so, in a form --dest reads back (a hex number without a letter needs the 0x).
    if (a.unit < 10) return fmt::format("{}.{}.{}", a.network, a.node, a.unit);
    const std::string hex = fmt::format("{:X}", a.unit);
    const bool letter = hex.find_first_of("ABCDEF") != std::string::npos;
    return fmt::format("{}.{}.{}{}", a.network, a.node, letter ? "" : "0x", hex);
}

int Output::usage(const std::string& message) {
    if (json_)
        std::printf(
            "%s\n",
            dump(nlohmann::json{{"error", {{"kind", "usage"}, {"message", message}}}}).c_str());
    std::fprintf(stderr, "fins: %s\n", message.c_str());
    return exit_usage;
}

int Output::failure(std::error_code ec, const std::string& context) {
    const ErrorKind kind = kind_of(ec);
    std::string hint;
    // 0201: the request named a node the PLC is not. Ask the PLC which node it is.
    if (relay_ && kind == ErrorKind::end_code) {
        // A router on the way answered, not the destination (W342 5-1-3 bit 15).
        hint = fmt::format(
            "relay error: the router at network {} node {} could not pass the "
            "command on (check its routing tables)",
            relay_->network, relay_->node);
    } else if (ec == make_error_code(EndCode::destination_node_not_in_network) &&
               target_ != nullptr) {
        if (auto found = discover_node(*target_)) {
            // Keep the unit the request was for (loop-read's Inner Board E1): only the
            // node was wrong.
            if (const auto asked = parse_node_address(target_->dest);
                asked && !target_->dest.empty())
                found->address.unit = asked->unit;
            hint = fmt::format("the PLC at {} is node {}: use --dest {}", endpoint(*target_),
                               found->address.node, node_text(found->address));
        }
    } else if (ec == make_error_code(EndCode::unit_missing)) {
        hint = "no such unit at that node: the CPU Unit is unit 0 (--dest NET.NODE.0)";
    } else if (ec == make_error_code(EndCode::read_only) && target_ != nullptr) {
        // W342 5-1-3 2101: read-only, "or protected using a switch setting": DIP switch
        // pin 1 (UM write protection, 5-1-2), which 05 01 reports as bit 0.
        // finsd sets the pin with --dip-write-protection or [protection] dip_write.
        const auto dip = read_dip_switch(*target_);
        if (dip && (*dip & 0x01) != 0)
            hint =
                "the CPU Unit's DIP switch pin 1 is ON: user memory is write-protected "
                "(W342 5-1-2); turn pin 1 OFF to write (finsd: started with "
                "--dip-write-protection or [protection] dip_write = true)";
        else if (dip)
            hint = "DIP switch pin 1 is OFF: the area or file itself is read-only";
    } else if (ec == make_error_code(EndCode::write_protected) && local_) {
        // W342 5-1-3 2102: program protection, or the PLC Setup's write protection from
        // the network, which lets through only the nodes it lists (by SA1).
        hint = fmt::format(
            "fins sent as source node {}; network write protection lets only the nodes it "
            "lists write (--source NET.NODE sends as another node, `fins probe` shows the "
            "node in use). It is set in the PLC Setup (finsd: --network-write-protection "
            "and --protect-node, [protection] network_write and nodes, or `finsd ctl "
            "write-protect off`)",
            node_text(*local_));
    } else if (ec == make_error_code(EndCode::no_access_right) && target_ != nullptr) {
        // W342 5-1-3 3001: another device holds the access right; its 0C 01 refusal names it.
        if (const auto holder = access_right_holder(*target_))
            hint = access_right_hint(*holder);
        else
            hint =
                "no node holds the access right any more: run the command again "
                "(`fins access acquire` takes it first)";
    }
    std::string meaning = ec.message();
    if (explained_ && kind == ErrorKind::end_code && ec == make_error_code(explained_->first))
        meaning = fmt::format("0x{:04X}: {}", ec.value(), explained_->second);
    // A transport error names the endpoint it happened with (issue 7 item 3):
    // "127.0.0.1:9600: connection refused".
    const std::string message = kind == ErrorKind::transport && target_ != nullptr
                                    ? fmt::format("{}: {}", endpoint(*target_), ec.message())
                                    : meaning;
    if (json_) {
        nlohmann::json e{{"kind", kind_name(kind)}, {"message", message}, {"context", context}};
        if (kind == ErrorKind::end_code) {
            e["end_code"] = fmt::format("{:04X}", ec.value());
            const auto* info = find_end_code(static_cast<std::uint16_t>(ec.value()));
            e["name"] = info ? std::string(info->name) : "unknown";
        }
        if (relay_ && kind == ErrorKind::end_code)
            e["relay_error"] = {{"network", relay_->network}, {"node", relay_->node}};
        if (!hint.empty()) e["hint"] = hint;
        std::printf("%s\n", dump(nlohmann::json{{"error", e}}).c_str());
    }
    if (kind == ErrorKind::end_code)
        std::fprintf(stderr, "fins: %s: the PLC answered %s\n", context.c_str(), meaning.c_str());
    else
        std::fprintf(stderr, "fins: %s: %s\n", context.c_str(), message.c_str());
    if (!hint.empty()) std::fprintf(stderr, "fins: %s\n", hint.c_str());
    switch (kind) {
        case ErrorKind::usage:
            return exit_usage;
        case ErrorKind::end_code:
            return exit_end_code;
        case ErrorKind::transport:
            break;
    }
    return exit_transport;
}

void Output::note_flags(ResponseCode code) {
    flags_tracked_ = true;
    fatal_ = fatal_ || code.fatal_cpu_error();
    non_fatal_ = non_fatal_ || code.non_fatal_cpu_error();
}

void Output::print(const nlohmann::json& doc, const std::string& text) {
    if (json_) {
        nlohmann::json d = doc;
        if (flags_tracked_) {
            d["fatal_cpu_error"] = fatal_;
            d["non_fatal_cpu_error"] = non_fatal_;
        }
        std::printf("%s\n", dump(d).c_str());
    } else {
        std::fputs(text.c_str(), stdout);
    }
    // The values are good (bits 6/7 ride on a normal completion, W342 5-1-3), but the
    // CPU Unit has an error someone should look at.
    if (fatal_ || non_fatal_) {
        std::fflush(stdout);
        std::fprintf(
            stderr,
            "fins: note: the answer carried the %s CPU error flag (%s): see `fins status`\n",
            fatal_ ? "fatal" : "non-fatal", fatal_ ? "0080" : "0040");
    }
}

Progress::Progress(std::string what, std::size_t total, std::string unit)
    : what_(std::move(what)),
      unit_(std::move(unit)),
      total_(total),
      active_(::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() {
    if (shown_) std::fputs("\r\x1b[K", stderr);
}

void Progress::update(std::size_t done) {
    // Only when the transfer takes more than one request: short ones finish before a
    // line could be read.
    if (!active_ || (total_ != 0 && done >= total_)) return;
    shown_ = true;
    if (total_ == 0)  // the end is not known in advance (program-read to bit 15)
        std::fprintf(stderr, "\r%s: %zu %s", what_.c_str(), done, unit_.c_str());
    else
        std::fprintf(stderr, "\r%s: %zu/%zu %s (%zu%%)", what_.c_str(), done, total_, unit_.c_str(),
                     done * 100 / total_);
    std::fflush(stderr);
}

}  // namespace fins::cli
