// `fins files save / load / compare` helpers (22 0A / 0B / 0C, W342 5-3-39 .. 5-3-41):
// - the argument list, in the orders docs/file-memory.md gives;
// - after the PLC answered a compare with 2007: the answer only counts what matched
//   before the first difference, so the file is fetched (22 02) and the area read
//   (01 01, 02 01, 03 06) to say where they first differ, both values, and how many
//   items differ.
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/verbs_files_transfer.hpp"

#include "cli/fins/commands.hpp"
#include "fins/commands/file_memory.hpp"
#include "fins/commands/parameter_area.hpp"
#include "fins/commands/program_area.hpp"

namespace fins::cli {

TransferArguments transfer_arguments(FileTransferMode mode, const std::vector<std::string>& v) {
    const auto number = [](const std::string& t) {
        return !t.empty() && t.size() <= 5 &&
               std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    const bool save = mode == FileTransferMode::to_file;
    const char* form =
        save ? "files save WHAT PLCFILE [COUNT] (or WHAT COUNT PLCFILE)"
             : (mode == FileTransferMode::from_file ? "files load PLCFILE WHAT [COUNT]"
                                                    : "files compare PLCFILE WHAT [COUNT]");
    TransferArguments a;
    if (v.size() < 2 || v.size() > 3) {
        a.problem = fmt::format(
            "usage: {}, e.g. {} (WHAT: a word address with COUNT, a parameter area, or "
            "program)",
            form, save ? "files save D100 /D100.IOM 10" : "files load /D100.IOM D100 10");
        return a;
    }
    std::string count;
    if (save) {
        a.what = v[0];
        // "D100 10 /D100.IOM": a number before something that is not one is the count.
        const bool count_first = v.size() == 3 && number(v[1]) && !number(v[2]);
        a.plc = count_first ? v[2] : v[1];
        if (v.size() == 3) count = count_first ? v[1] : v[2];
    } else {
        a.plc = v[0];
        a.what = v[1];
        if (v.size() == 3) count = v[2];
    }
    if (!count.empty()) {
        if (!number(count))
            a.problem = fmt::format("COUNT '{}' is not a number of words (1-65535); usage: {}",
                                    count, form);
        else
            a.count = static_cast<unsigned>(std::stoul(count));
    }
    return a;
}

namespace {

// Big-endian `unit`-byte value at item i.
std::uint32_t value_at(Bytes b, std::size_t i, std::size_t unit) {
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < unit; ++k)
        v = (v << 8) | b[i * unit + k];
    return v;
}

struct Difference {
    std::size_t compared = 0;  // items present on both sides
    std::size_t differ = 0;
    std::size_t first = 0;  // valid when differ > 0
    std::uint32_t file_value = 0;
    std::uint32_t plc_value = 0;
};

Difference compare_items(Bytes file, Bytes plc, std::size_t unit) {
    Difference d;
    d.compared = std::min(file.size(), plc.size()) / unit;
    for (std::size_t i = 0; i < d.compared; ++i) {
        const auto f = value_at(file, i, unit);
        const auto p = value_at(plc, i, unit);
        if (f == p) continue;
        if (d.differ++ == 0) {
            d.first = i;
            d.file_value = f;
            d.plc_value = p;
        }
    }
    return d;
}

Result<std::vector<std::uint8_t>> parameter_bytes(Client& client, const ParameterAreaInfo& area) {
    std::vector<std::uint8_t> out;
    out.reserve(std::size_t{area.words} * 2);
    // 02 01 answers area, start, count (6 bytes), then the words; bounded by the area.
    while (out.size() / 2 < area.words) {
        const auto n = std::min(fit(max_parameter_words, client.max_response_data(), 6, 2),
                                area.words - out.size() / 2);
        const auto r =
            client.send(ParameterAreaRead{area.code, static_cast<std::uint16_t>(out.size() / 2),
                                          static_cast<std::uint16_t>(n), false});
        if (!r) return Unexpected(r.error());
        if (r->words.size() != n)
            return Unexpected(make_error_code(ClientError::malformed_response));
        for (const auto w : r->words) {
            out.push_back(static_cast<std::uint8_t>(w >> 8));
            out.push_back(static_cast<std::uint8_t>(w));
        }
    }
    return out;
}

// The UM from 0 up to `limit` bytes (or its end). A block cut at the UM's end answers
// 1104 with data (5-3-7's rule): the end, not a failure.
Result<std::vector<std::uint8_t>> program_bytes(Client& client, std::size_t limit) {
    std::vector<std::uint8_t> out;
    const std::size_t block = fit(max_program_read_bytes / 4, client.max_response_data(), 8, 4) * 4;
    for (bool last = false; !last && out.size() < limit;) {
        const ProgramAreaRead command{program_number_all, static_cast<std::uint32_t>(out.size()),
                                      static_cast<std::uint16_t>(block), false};
        std::array<std::uint8_t, 8> parameters{};
        ByteWriter w(parameters);
        command.encode(w);
        const auto r = client.send_raw(ProgramAreaRead::code, w.written());
        if (!r) return Unexpected(r.error());
        const bool cut = r->code.end_code() == EndCode::address_range_exceeded && !r->data.empty();
        if (!r->code.ok() && !cut) return Unexpected(make_error_code(r->code.end_code()));
        const auto b = command.decode_response(r->data);
        if (!b) return Unexpected(b.error());
        if (b->data.empty() && !b->last && !cut)
            return Unexpected(make_error_code(ClientError::malformed_response));
        out.insert(out.end(), b->data.begin(), b->data.end());
        last = b->last || cut;
    }
    return out;
}

std::string word_address(const Address& start, std::size_t i) {
    Address a = start;
    a.word = static_cast<decltype(a.word)>(a.word + i);
    return format_address(a);
}

}  // namespace

// "3 of 10 words differ; the first is D103: file 1234, PLC 0000", or the reason it could
// not be found out.
std::string describe_file_difference(Client& client, std::uint16_t disk,
                                     const std::string& directory, const FileName& file,
                                     const CompareTarget& target) {
    const auto stored = get_file(client, disk, directory, file);
    if (!stored) return "the file could not be read back: " + stored.error().message();
    const Bytes body = stored->size() < data_file_header_size
                           ? Bytes{}
                           : Bytes(*stored).subspan(data_file_header_size);
    switch (target.kind) {
        case CompareTarget::Kind::words: {
            const auto words = client.read_words(target.start, target.count);
            if (!words) return "the words could not be read: " + words.error().message();
            std::vector<std::uint8_t> plc;
            for (const auto w : *words) {
                plc.push_back(static_cast<std::uint8_t>(w >> 8));
                plc.push_back(static_cast<std::uint8_t>(w));
            }
            const auto d = compare_items(body.first(std::min(body.size(), plc.size())), plc, 2);
            std::string text;
            if (d.differ != 0)
                text = fmt::format("{} of {} differ; the first is {}: file {:04X}, PLC {:04X}",
                                   d.differ, plural(d.compared, "word"),
                                   word_address(target.start, d.first), d.file_value, d.plc_value);
            if (body.size() / 2 < target.count)
                text += fmt::format("{}the file holds {}, not {}", text.empty() ? "" : "; ",
                                    plural(body.size() / 2, "word"), target.count);
            return text;
        }
        case CompareTarget::Kind::parameters: {
            const auto plc = parameter_bytes(client, *target.area);
            if (!plc) return "the parameter area could not be read: " + plc.error().message();
            const auto d = compare_items(body, *plc, 2);
            std::string text;
            if (d.differ != 0)
                text = fmt::format(
                    "{} of {} differ; the first is word {} of {} ({:04X}): file {:04X}, PLC "
                    "{:04X}",
                    d.differ, plural(d.compared, "word"), d.first, target.area->id,
                    target.area->code, d.file_value, d.plc_value);
            if (body.size() != plc->size())
                text +=
                    fmt::format("{}the file holds {}, the area {}", text.empty() ? "" : "; ",
                                plural(body.size() / 2, "word"), plural(plc->size() / 2, "word"));
            return text;
        }
        case CompareTarget::Kind::program: {
            // One 4-byte step more than the file tells whether the PLC's program is longer.
            const auto um = program_bytes(client, body.size() + 4);
            if (!um) return "the program could not be read: " + um.error().message();
            const auto d = compare_items(body, *um, 1);
            std::string text;
            if (d.differ != 0)
                text = fmt::format(
                    "{} of {} differ; the first is byte {:08X}: file {:02X}, PLC {:02X}", d.differ,
                    plural(d.compared, "byte"), d.first, d.file_value, d.plc_value);
            const bool longer = std::any_of(
                um->begin() + static_cast<std::ptrdiff_t>(std::min(um->size(), body.size())),
                um->end(), [](std::uint8_t b) { return b != 0; });
            if (longer)
                text += fmt::format("{}the PLC's program goes on after the file's {}",
                                    text.empty() ? "" : "; ", plural(body.size(), "byte"));
            return text;
        }
    }
    return {};
}

}  // namespace fins::cli
