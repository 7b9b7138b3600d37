// FINS over Host Link (W342 3-5, 5-3-1; fins-frames.md section 4). See fins/host_link.hpp.
#include "fins/host_link.hpp"
#include "codec/hex.hpp"

#include <algorithm>
#include <string>

#include <fmt/core.h>

namespace fins {
namespace {

constexpr char hex_digits[] = "0123456789ABCDEF";
// "@" UU "FA": the part every frame starts with.
constexpr std::size_t prefix_chars = 5;
// FCS + "*" CR.
constexpr std::size_t trailer_chars = 4;
// ICF DA2 SA2 SID (direct) / the whole header (network), in bytes.
constexpr std::size_t direct_header_bytes = 4;

constexpr std::string_view header_text(HostLinkHeaderCode code) noexcept {
    return code == HostLinkHeaderCode::of ? "OF" : "FA";
}

// Writes characters while they fit; `ok` turns false once one did not.
struct AsciiWriter {
    MutableBytes out;
    std::size_t pos = 0;
    bool ok = true;
    void put(char c) noexcept {
        if (pos >= out.size()) {
            ok = false;
            return;
        }
        out[pos++] = static_cast<std::uint8_t>(c);
    }
    void text(std::string_view s) noexcept {
        for (char c : s)
            put(c);
    }
    void hex(std::uint8_t b) noexcept {
        put(hex_digits[b >> 4]);
        put(hex_digits[b & 0x0F]);
    }
    void hex(Bytes bytes) noexcept {
        for (auto b : bytes)
            hex(b);
    }
    void unit(std::uint8_t u) noexcept {
        put(static_cast<char>('0' + u / 10));
        put(static_cast<char>('0' + u % 10));
    }
    // FCS over everything written so far, then "*" CR.
    void finish() noexcept {
        const auto fcs = host_link_fcs(Bytes{out.data(), std::min(pos, out.size())});
        hex(fcs);
        put('*');
        put('\r');
    }
};

// Two hex characters -> a byte, or -1.
int hex_byte(Bytes two) noexcept {
    return hex::byte_value(static_cast<char>(two[0]), static_cast<char>(two[1]));
}

class HostLinkEndCodeCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.host_link_end_code"; }
    std::string message(int value) const override {
        const char* text = "unknown Host Link end code";
        switch (static_cast<HostLinkEndCode>(value)) {
            case HostLinkEndCode::normal:
                text = "normal completion";
                break;
            case HostLinkEndCode::not_executable_in_run:
                text = "not executable in RUN mode";
                break;
            case HostLinkEndCode::not_executable_in_monitor:
                text = "not executable in MONITOR mode";
                break;
            case HostLinkEndCode::um_write_protected:
                text = "UM write-protected";
                break;
            case HostLinkEndCode::address_over:
                text = "address over";
                break;
            case HostLinkEndCode::not_executable_in_program:
                text = "not executable in PROGRAM mode";
                break;
            case HostLinkEndCode::fcs_error:
                text = "FCS error";
                break;
            case HostLinkEndCode::format_error:
                text = "format error";
                break;
            case HostLinkEndCode::entry_number_error:
                text = "entry number data error";
                break;
            case HostLinkEndCode::command_not_supported:
                text = "command not supported";
                break;
            case HostLinkEndCode::frame_length_error:
                text = "frame length error";
                break;
            case HostLinkEndCode::not_executable:
                text = "not executable";
                break;
            case HostLinkEndCode::io_table_not_created:
                text = "could not create I/O table";
                break;
            case HostLinkEndCode::cpu_unit_error:
                text = "not executable due to CPU Unit CPU error";
                break;
            case HostLinkEndCode::user_memory_protected:
                text = "user memory protected";
                break;
            case HostLinkEndCode::aborted_fcs_error:
                text = "aborted: FCS error";
                break;
            case HostLinkEndCode::aborted_format_error:
                text = "aborted: format error";
                break;
            case HostLinkEndCode::aborted_entry_number_error:
                text = "aborted: entry number data error";
                break;
            case HostLinkEndCode::aborted_frame_length_error:
                text = "aborted: frame length error";
                break;
        }
        return fmt::format("{} (Host Link end code {:02X})", text, value);
    }
};

class HostLinkCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.host_link"; }
    std::string message(int value) const override {
        switch (static_cast<HostLinkError>(value)) {
            case HostLinkError::bad_fcs:
                return "answer with a bad FCS (Host Link)";
            case HostLinkError::format:
                return "answer is not a Host Link FINS response";
            case HostLinkError::too_long:
                return "frame over the Host Link length limit";
            case HostLinkError::wrong_unit:
                return "answer from another Host Link unit number";
        }
        return "unknown Host Link error";
    }
};

}  // namespace

const std::error_category& host_link_end_code_category() noexcept {
    static const HostLinkEndCodeCategory category;
    return category;
}
std::error_code make_error_code(HostLinkEndCode e) noexcept {
    return {static_cast<int>(e), host_link_end_code_category()};
}
const std::error_category& host_link_category() noexcept {
    static const HostLinkCategory category;
    return category;
}
std::error_code make_error_code(HostLinkError e) noexcept {
    return {static_cast<int>(e), host_link_category()};
}

std::uint8_t host_link_fcs(Bytes text) noexcept {
    std::uint8_t fcs = 0;
    for (auto c : text)
        fcs ^= c;
    return fcs;
}

Result<std::size_t> encode_host_link_command(std::uint8_t unit, std::uint8_t wait,
                                             HostLinkForm form, Bytes fins_command,
                                             MutableBytes out, HostLinkHeaderCode code) noexcept {
    if (unit > host_link_max_unit || wait > 0x0F ||
        fins_command.size() < header_size + command_code_size)
        return Unexpected(make_error_code(HostLinkError::format));
    if (fins_command.size() > host_link_max_fins_command)
        return Unexpected(make_error_code(HostLinkError::too_long));
    AsciiWriter w{out};
    w.put('@');
    w.unit(unit);
    w.text(header_text(code));
    w.put(hex_digits[wait]);
    if (form == HostLinkForm::direct) {
        // ICF "00" (W342 3-5), DA2, SA2, SID.
        w.hex(std::uint8_t{0x00});
        w.hex(fins_command[5]);
        w.hex(fins_command[8]);
        w.hex(fins_command[9]);
        w.hex(fins_command.subspan(header_size));
    } else {
        w.hex(fins_command);
    }
    w.finish();
    if (!w.ok) return Unexpected(make_error_code(HostLinkError::too_long));
    return w.pos;
}

Result<std::size_t> encode_host_link_response(std::uint8_t unit, HostLinkForm form,
                                              Bytes fins_response, MutableBytes out,
                                              HostLinkHeaderCode code) noexcept {
    if (unit > host_link_max_unit ||
        fins_response.size() < header_size + command_code_size + end_code_size)
        return Unexpected(make_error_code(HostLinkError::format));
    if (fins_response.size() > host_link_max_fins_response)
        return Unexpected(make_error_code(HostLinkError::too_long));
    AsciiWriter w{out};
    w.put('@');
    w.unit(unit);
    w.text(header_text(code));
    w.hex(static_cast<std::uint8_t>(HostLinkEndCode::normal));
    if (form == HostLinkForm::direct) {
        w.hex(icf_response);  // "40"
        w.hex(fins_response[5]);
        w.hex(fins_response[8]);
        w.hex(fins_response[9]);
        w.hex(fins_response.subspan(header_size));
    } else {
        w.hex(fins_response);
    }
    w.finish();
    if (!w.ok) return Unexpected(make_error_code(HostLinkError::too_long));
    return w.pos;
}

std::size_t encode_host_link_error(std::uint8_t unit, HostLinkEndCode end_code, MutableBytes out,
                                   HostLinkHeaderCode code) noexcept {
    AsciiWriter w{out};
    w.put('@');
    w.unit(std::min(unit, host_link_max_unit));
    w.text(header_text(code));
    w.hex(static_cast<std::uint8_t>(end_code));
    w.finish();
    return w.ok ? w.pos : 0;
}

tl::expected<HostLinkFrame, HostLinkDecodeError> decode_host_link(Bytes frame, bool response,
                                                                  MutableBytes fins_out) noexcept {
    using Error = tl::unexpected<HostLinkDecodeError>;
    HostLinkDecodeError e;
    if (frame.size() < prefix_chars + trailer_chars || frame[0] != '@' ||
        frame[frame.size() - 2] != '*' || frame[frame.size() - 1] != '\r')
        return Error(e);
    if (frame[1] < '0' || frame[1] > '9' || frame[2] < '0' || frame[2] > '9') return Error(e);
    const auto unit = static_cast<std::uint8_t>((frame[1] - '0') * 10 + (frame[2] - '0'));
    if (unit > host_link_max_unit) return Error(e);
    e.unit = unit;

    const std::size_t text_end = frame.size() - trailer_chars;
    const int fcs = hex_byte(frame.subspan(text_end, 2));
    if (fcs < 0 || fcs != host_link_fcs(frame.first(text_end))) {
        e.error = HostLinkError::bad_fcs;
        return Error(e);
    }
    if (frame.size() > (response ? host_link_max_response_chars : host_link_max_command_chars)) {
        e.error = HostLinkError::too_long;
        return Error(e);
    }
    HostLinkFrame f;
    f.unit = unit;
    f.response = response;
    if (frame[3] == 'F' && frame[4] == 'A') {
        f.header_code = HostLinkHeaderCode::fa;
    } else if (frame[3] == 'O' && frame[4] == 'F') {
        f.header_code = HostLinkHeaderCode::of;
    } else {
        e.not_fins = true;
        return Error(e);
    }

    // After the prefix: the wait digit (command) or the end code (response).
    std::size_t pos = prefix_chars;
    if (response) {
        if (text_end - pos < 2) return Error(e);
        const int end_code = hex_byte(frame.subspan(pos, 2));
        if (end_code < 0) return Error(e);
        f.end_code = static_cast<HostLinkEndCode>(end_code);
        pos += 2;
        if (f.end_code != HostLinkEndCode::normal) {
            // An error answer carries no FINS part (our choice, docs/serial.md "Host Link end
            // codes").
            if (pos != text_end) return Error(e);
            return f;
        }
    } else {
        if (text_end - pos < 1) return Error(e);
        const int wait = hex::digit_value(static_cast<char>(frame[pos]));
        if (wait < 0) return Error(e);
        f.wait = static_cast<std::uint8_t>(wait);
        pos += 1;
    }

    const std::size_t text_chars = text_end - pos;
    if (text_chars % 2 != 0 || text_chars < 2) return Error(e);
    const std::size_t bytes = text_chars / 2;
    // Decode the first byte (ICF) to learn the form.
    const int icf = hex_byte(frame.subspan(pos, 2));
    if (icf < 0) return Error(e);
    f.form = (icf & icf_gateway) != 0 ? HostLinkForm::network : HostLinkForm::direct;
    const std::size_t min_bytes =
        (f.form == HostLinkForm::direct ? direct_header_bytes : header_size) + command_code_size +
        (response ? end_code_size : 0);
    const std::size_t fins_size =
        f.form == HostLinkForm::direct ? bytes - direct_header_bytes + header_size : bytes;
    if (bytes < min_bytes) return Error(e);
    if (fins_size > fins_out.size() ||
        fins_size > (response ? host_link_max_fins_response : host_link_max_fins_command)) {
        e.error = HostLinkError::too_long;
        return Error(e);
    }
    std::size_t out = 0;
    if (f.form == HostLinkForm::direct) {
        // Fill the header fields the direct form leaves out: local network and PLC.
        out = header_size;
        std::fill(fins_out.begin(), fins_out.begin() + header_size, std::uint8_t{0});
        fins_out[2] = default_gateway_count;
    }
    for (std::size_t i = 0; i < bytes; ++i) {
        const int b = hex_byte(frame.subspan(pos + 2 * i, 2));
        if (b < 0) return Error(e);
        const auto byte = static_cast<std::uint8_t>(b);
        if (f.form == HostLinkForm::direct && i < direct_header_bytes) {
            // ICF DA2 SA2 SID into the 10-byte header.
            constexpr std::size_t slot[direct_header_bytes] = {0, 5, 8, 9};
            fins_out[slot[i]] = byte;
            continue;
        }
        fins_out[out++] = byte;
    }
    // The response bit must match the kind of frame expected.
    if (((fins_out[0] & icf_response) != 0) != response) return Error(e);
    f.fins_size = out;
    return f;
}

HostLinkEndCode host_link_answer_for(const HostLinkDecodeError& e) noexcept {
    if (e.not_fins) return HostLinkEndCode::command_not_supported;
    switch (e.error) {
        case HostLinkError::bad_fcs:
            return HostLinkEndCode::fcs_error;
        case HostLinkError::too_long:
            return HostLinkEndCode::frame_length_error;
        case HostLinkError::format:
        case HostLinkError::wrong_unit:
            break;
    }
    return HostLinkEndCode::format_error;
}

HostLinkScan scan_host_link(Bytes buffer, std::size_t limit) noexcept {
    HostLinkScan s;
    if (buffer.empty()) return s;
    if (buffer[0] != '@') {
        const auto at = std::find(buffer.begin(), buffer.end(), std::uint8_t{'@'});
        s.status = HostLinkScan::Status::garbage;
        s.consumed = static_cast<std::size_t>(at - buffer.begin());
        return s;
    }
    const auto window = buffer.first(std::min(buffer.size(), limit));
    // A second "@" before the CR starts another frame: what came before is garbage (hex
    // text never holds "@").
    const auto end = std::find_if(window.begin() + 1, window.end(),
                                  [](std::uint8_t c) { return c == '\r' || c == '@'; });
    if (end != window.end() && *end == '@') {
        s.status = HostLinkScan::Status::garbage;
        s.consumed = static_cast<std::size_t>(end - window.begin());
        return s;
    }
    const auto cr = end;
    if (cr != window.end()) {
        s.status = HostLinkScan::Status::frame;
        s.consumed = static_cast<std::size_t>(cr - window.begin()) + 1;
        s.frame = buffer.first(s.consumed);
        return s;
    }
    if (buffer.size() >= limit) {
        s.status = HostLinkScan::Status::too_long;
        s.consumed = limit;
    }
    return s;
}

}  // namespace fins
