// fins_compowayf_sim DEVICE [--node N] [--garble]: a SIMULATED Omron temperature
// controller (E5_C-like) answering CompoWay/F on a serial device, for tests and demos of
// finsd's Serial Gateway (28 03). Not a model of any real controller's control loop:
// it holds a variable area and answers the services of frames-serial-files.md 1.5 with
// the end and response codes of 1.3 / 1.4.
//
//   01 01 read variable area   C0 (monitor, read-only), C1, C3 (setup) as double words,
//                              80, 81, 83 the same areas as words; 256 elements each
//   01 02 write variable area  needs communications writing ON (30 05 00 01), else 2203;
//                              C0/80 are read-only (3003)
//   05 03 read controller attributes, 06 01 read controller status, 08 01 echoback,
//   30 05 operation command    00 communications writing, 01 RUN/STOP, 02-0E accepted
// Frame errors: BCC 13, non-hex text 14, sub-address other than "00" 16. Another node
// gets no answer; node "XX" (broadcast) is executed and not answered.
// --garble flips the BCC of every answer (the gateway must answer 0206).
#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "fins/compoway_f.hpp"

namespace {

using fins::Bytes;
using fins::ByteWriter;
namespace cf = fins::compoway_f;

constexpr std::size_t elements = 256;

struct Controller {
    std::array<std::array<std::uint32_t, elements>, 3> areas{};  // C0, C1, C3
    bool comms_writing = false;
    bool running = true;
};

int hex_digit(std::uint8_t c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

// Parses n hex digits; -1 when one is not a hex digit.
long hex_value(Bytes text, std::size_t at, std::size_t n) {
    long v = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const int d = hex_digit(text[at + i]);
        if (d < 0) return -1;
        v = v * 16 + d;
    }
    return v;
}

void put_hex(std::string& out, std::uint32_t v, int digits) {
    static constexpr char d[] = "0123456789ABCDEF";
    for (int i = digits - 1; i >= 0; --i)
        out += d[(v >> (4 * i)) & 0xF];
}

// Area index and digits per element of a variable type, or -1.
int area_of(long type, int& digits) {
    digits = (type & 0x40) != 0 ? 8 : 4;  // Cx double words, 8x words
    switch (type) {
        case 0xC0:
        case 0x80:
            return 0;
        case 0xC1:
        case 0x81:
            return 1;
        case 0xC3:
        case 0x83:
            return 2;
        default:
            return -1;
    }
}

// Runs one command; returns the response code and appends data to `data`.
std::string execute(Controller& c, std::string_view mrc_src, Bytes text, std::string& data) {
    for (auto b : text)
        if (hex_digit(b) < 0 && mrc_src != "0801") return "14";  // frame error marker
    if (mrc_src == "0101" || mrc_src == "0102") {
        const bool write = mrc_src == "0102";
        if (text.size() < 12) return "1002";
        if (!write && text.size() > 12) return "1001";
        int digits = 0;
        const int area = area_of(hex_value(text, 0, 2), digits);
        if (area < 0) return "1101";
        const long address = hex_value(text, 2, 4);
        if (hex_value(text, 6, 2) != 0) return "1100";
        const long count = hex_value(text, 8, 4);
        if (address >= static_cast<long>(elements)) return "1103";
        if (address + count > static_cast<long>(elements)) return "1104";
        if (count > (digits == 8 ? 25 : 50)) return "110B";
        if (!write) {
            for (long i = 0; i < count; ++i) {
                const auto v =
                    c.areas[static_cast<std::size_t>(area)][static_cast<std::size_t>(address + i)];
                put_hex(data, digits == 8 ? v : (v & 0xFFFFU), digits);
            }
            return "0000";
        }
        if (text.size() != 12 + static_cast<std::size_t>(count * digits)) return "1003";
        if (area == 0) return "3003";
        if (!c.comms_writing) return "2203";
        for (long i = 0; i < count; ++i)
            c.areas[static_cast<std::size_t>(area)][static_cast<std::size_t>(address + i)] =
                static_cast<std::uint32_t>(hex_value(text,
                                                     12 + static_cast<std::size_t>(i * digits),
                                                     static_cast<std::size_t>(digits)));
        return "0000";
    }
    if (mrc_src == "0503") {
        if (!text.empty()) return "1001";
        data = "E5CC-SIM  00D9";
        return "0000";
    }
    if (mrc_src == "0601") {
        if (!text.empty()) return "1001";
        data = c.running ? "0000" : "0100";
        return "0000";
    }
    if (mrc_src == "0801") {
        data.assign(text.begin(), text.end());
        return text.size() > 200 ? "1001" : "0000";
    }
    if (mrc_src == "3005") {
        if (text.size() < 4) return "1002";
        if (text.size() > 4) return "1001";
        const long code = hex_value(text, 0, 2);
        const long info = hex_value(text, 2, 2);
        if (code == 0x00 && info <= 1) {
            c.comms_writing = info == 1;
            return "0000";
        }
        if (!c.comms_writing) return "2203";
        if (code == 0x01 && info <= 1) {
            c.running = info == 0;
            return "0000";
        }
        if (code >= 0x02 && code <= 0x0E) return "0000";
        return "1100";
    }
    return "0401";
}

// The response body for one command body; empty when nothing is to be answered.
std::string respond(Controller& c, Bytes body, const std::string& node, bool bcc_ok) {
    if (body.size() < 2) return {};
    const std::string target(body.begin(), body.begin() + 2);
    const bool broadcast = target == "XX";
    if (target != node && !broadcast) return {};
    std::string out = target;
    if (!bcc_ok) return broadcast ? std::string{} : out + "0013";
    const auto command = cf::decode_command(body);
    if (!command || command->sub_address != std::array<std::uint8_t, 2>{'0', '0'})
        return broadcast ? std::string{} : out + "0016";
    const std::string_view mrc_src(reinterpret_cast<const char*>(command->command.data()), 4);
    std::string data;
    const std::string code = execute(c, mrc_src, command->text, data);
    if (broadcast) return {};
    if (code == "14") return out + "0014";
    out += "00";
    out += code == "0000" ? "00" : "0F";
    out.append(mrc_src);
    out += code;
    if (code == "0000") out += data;
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: fins_compowayf_sim DEVICE [--node N] [--garble]\n");
        return 2;
    }
    std::string node = "01";
    bool garble = false;
    for (int i = 2; i < argc; ++i) {
        const std::string_view a = argv[i];
        if (a == "--node" && i + 1 < argc) {
            const int n = std::atoi(argv[++i]);
            if (n < 0 || n > 99) return 2;
            node = {static_cast<char>('0' + n / 10), static_cast<char>('0' + n % 10)};
        } else if (a == "--garble") {
            garble = true;
        } else {
            std::fprintf(stderr, "fins_compowayf_sim: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    const int fd = ::open(argv[1], O_RDWR | O_NOCTTY);
    if (fd < 0) {
        std::fprintf(stderr, "fins_compowayf_sim: %s: %s\n", argv[1], std::strerror(errno));
        return 3;
    }
    termios t{};
    if (::tcgetattr(fd, &t) == 0) {
        ::cfmakeraw(&t);
        ::tcsetattr(fd, TCSANOW, &t);
    }
    Controller c;
    c.areas[0][0] = 25;   // C0 0000: process value
    c.areas[1][0] = 100;  // C1 0000: set point
    std::printf("ready\n");
    std::fflush(stdout);
    std::vector<std::uint8_t> rx;
    std::array<std::uint8_t, 256> buf{};
    for (;;) {
        const auto n = ::read(fd, buf.data(), buf.size());
        if (n <= 0) return 0;  // the line is gone
        rx.insert(rx.end(), buf.begin(), buf.begin() + n);
        for (;;) {
            const auto parsed = cf::parse_frame(rx);
            if (parsed.status == cf::FrameParse::Status::need_more) {
                rx.erase(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(parsed.consumed));
                break;
            }
            std::string answer;
            if (parsed.status != cf::FrameParse::Status::too_long)
                answer = respond(c, parsed.body, node,
                                 parsed.status == cf::FrameParse::Status::complete);
            rx.erase(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(parsed.consumed));
            if (answer.empty()) continue;
            std::vector<std::uint8_t> frame(answer.size() + 3);
            ByteWriter w(frame);
            cf::write_frame(
                w, Bytes{reinterpret_cast<const std::uint8_t*>(answer.data()), answer.size()});
            if (garble) frame.back() ^= 0x5A;
            if (::write(fd, frame.data(), w.size()) < 0) return 0;
        }
    }
}
