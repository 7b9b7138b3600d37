// 22 20 MEMORY CASSETTE TRANSFER (W342 5-3-43), on profiles with a Memory Cassette
// (Profile::memory_cassette: CP1H); the others answer 0401 (Profile::supports). The
// dispatcher applies the 5-1-2 row (PROGRAM mode only: 2206 RUN, 2205 MONITOR; 3001
// access right elsewhere; 2102 network write protection; write access log).
//
// The cassette holds one item per data type, in the data file formats of 22 0A .. 22 0C
// (48 header bytes of zeros, then the data), as <root>/cassette/AUTOEXEC.xxx:
//   bit 00 user program   AUTOEXEC.OBJ  UM bytes up to the last non-zero 4-byte unit
//   bit 02 parameter area AUTOEXEC.STD  all 8,000 words (16,048 bytes, CJ2SW p.272)
//   bit 06 data memory    AUTOEXEC.IOM  D0 .. the last DM word, high byte first
//   bits 03/04/05/07      AUTOEXEC.SYM/.CMT/.IDX/.DMI: symbol table, comments, program
//                         indices, DM initial values live in the CP1H's built-in flash,
//                         which finsd does not have: always empty (the header alone).
// Choices (docs/file-memory.md "Memory Cassette (22 20, CP1H)",
// tests/server/handlers/memory_cassette_test.cpp):
//   110C  disk other than 8003, unknown parameter, reserved designation bits (14-08,
//         01), bit 15 OFF with area bits ON (5-3-43 note), bit 15 ON with none.
//   2301  no cassette mounted.
//   0000  CPU -> cassette replaces the designated items and keeps the others.
//   0001  cassette -> CPU: "all" loads every item the cassette holds (2006 when it holds
//         none); individual areas must all be held (2006 otherwise), nothing is loaded
//         then. An item whose size does not fit its area: 250F, nothing loaded.
//   0002  verify: the items as 0001 selects them; a difference: 2007.
//   2101  DIP switch UM write protection with the user program in the transfer, both
//         ways (5-3-43 note: CPU -> cassette; 5-1-2 note 4: cassette -> program area).
//   8000  the stored data type: the items held (bit 01, FB sources, never: finsd has none).
#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "fins/commands/memory_cassette.hpp"
#include "fins/commands/parameter_area.hpp"
#include "fins/commands/program_area.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

EndCode execute(HandlerContext& context, const MemoryCassetteTransfer& command, ByteWriter& out);

namespace {

struct Item {
    std::uint16_t bit;
    const char* file;
};

constexpr std::array<Item, 7> items{{{cassette_program, "AUTOEXEC.OBJ"},
                                     {cassette_parameters, "AUTOEXEC.STD"},
                                     {cassette_symbol_table, "AUTOEXEC.SYM"},
                                     {cassette_comments, "AUTOEXEC.CMT"},
                                     {cassette_program_indices, "AUTOEXEC.IDX"},
                                     {cassette_dm, "AUTOEXEC.IOM"},
                                     {cassette_dm_initial_values, "AUTOEXEC.DMI"}}};

constexpr std::size_t header_size = plc::data_file_header_size;

std::vector<std::uint8_t> words_file(std::span<const std::uint16_t> words) {
    std::vector<std::uint8_t> out(header_size, 0);
    out.reserve(header_size + words.size() * 2);
    for (const auto w : words) {
        out.push_back(static_cast<std::uint8_t>(w >> 8));
        out.push_back(static_cast<std::uint8_t>(w));
    }
    return out;
}

// The UM bytes a save keeps: up to the last non-zero 4-byte unit (as 22 0C).
std::span<const std::uint8_t> used_program(std::span<const std::uint8_t> um) noexcept {
    std::size_t used = um.size();
    while (used > 0 && um[used - 1] == 0)
        --used;
    used = (used + program_alignment - 1) / program_alignment * program_alignment;
    return um.first(std::min(used, um.size()));
}

// What the CPU Unit holds for one data type, in the item's file format.
std::vector<std::uint8_t> snapshot(plc::Plc& plc, std::uint16_t bit) {
    switch (bit) {
        case cassette_program: {
            std::vector<std::uint8_t> out(header_size, 0);
            const auto used = used_program(plc.program().bytes());
            out.insert(out.end(), used.begin(), used.end());
            return out;
        }
        case cassette_parameters:
            return words_file(plc.parameters().words(parameter_area_all));
        case cassette_dm:
            return words_file(plc.memory().words(Region::dm));
        default:
            return std::vector<std::uint8_t>(header_size, 0);
    }
}

// Does a stored item fit the CPU Unit's area? (The host file may have been edited.)
bool fits(plc::Plc& plc, std::uint16_t bit, const std::vector<std::uint8_t>& file) {
    if (file.size() < header_size) return false;
    const auto body = file.size() - header_size;
    switch (bit) {
        case cassette_program:
            return body <= plc.program().bytes().size();
        case cassette_parameters:
            return body == plc.parameters().words(parameter_area_all).size() * 2;
        case cassette_dm:
            return body == plc.memory().words(Region::dm).size() * 2;
        default:
            return true;
    }
}

void restore(plc::Plc& plc, std::uint16_t bit, const std::vector<std::uint8_t>& file) {
    const auto body = Bytes(file).subspan(header_size);
    const auto to_words = [&](std::span<std::uint16_t> words) {
        for (std::size_t i = 0; i < words.size(); ++i)
            words[i] = static_cast<std::uint16_t>((body[2 * i] << 8) | body[2 * i + 1]);
    };
    switch (bit) {
        case cassette_program: {
            auto um = plc.program().bytes();
            std::fill(um.begin(), um.end(), std::uint8_t{0});
            std::copy(body.begin(), body.end(), um.begin());
            break;
        }
        case cassette_parameters:
            to_words(plc.parameters().words(parameter_area_all));
            break;
        case cassette_dm:
            to_words(plc.memory().words(Region::dm));
            break;
        default:  // areas finsd does not have: nothing to restore
            break;
    }
}

bool valid_operation(std::uint16_t op) noexcept {
    switch (static_cast<CassetteOperation>(op)) {
        case CassetteOperation::save:
        case CassetteOperation::load:
        case CassetteOperation::verify:
        case CassetteOperation::initialize:
        case CassetteOperation::read_type:
            return true;
    }
    return false;
}

// The area bits a transfer or verify designates, or 0 when the designation is invalid.
std::uint16_t designated(std::uint16_t designation) noexcept {
    constexpr std::uint16_t reserved =
        static_cast<std::uint16_t>(~(cassette_individual | cassette_areas));
    if ((designation & reserved) != 0) return 0;
    const auto areas = static_cast<std::uint16_t>(designation & cassette_areas);
    if ((designation & cassette_individual) == 0) return areas == 0 ? cassette_areas : 0;
    return areas;
}

using Loaded = std::vector<std::pair<std::uint16_t, std::vector<std::uint8_t>>>;

// The items a load or verify works on (see the rules above), or an end code.
Result<Loaded> gather(plc::Plc& plc, std::uint16_t areas, bool all) {
    Loaded loaded;
    for (const auto& item : items) {
        if ((areas & item.bit) == 0) continue;
        auto content = plc.files().cassette_item(item.file);
        if (!content) return Unexpected(content.error());
        if (!*content) {
            if (all) continue;
            return Unexpected(make_error_code(EndCode::read_file_missing));
        }
        if (!fits(plc, item.bit, **content))
            return Unexpected(make_error_code(EndCode::memory_error));
        loaded.emplace_back(item.bit, std::move(**content));
    }
    if (loaded.empty()) return Unexpected(make_error_code(EndCode::read_file_missing));
    return loaded;
}

}  // namespace

// 5-3-43.
EndCode execute(HandlerContext& context, const MemoryCassetteTransfer& command, ByteWriter& out) {
    if (command.disk != disk_memory_cassette || !valid_operation(command.operation))
        return EndCode::parameter_error;
    const auto op = static_cast<CassetteOperation>(command.operation);
    const bool transfer = op == CassetteOperation::save || op == CassetteOperation::load ||
                          op == CassetteOperation::verify;
    const std::uint16_t areas = transfer ? designated(command.designation) : 0;
    if (transfer && areas == 0) return EndCode::parameter_error;
    auto& plc = context.plc;
    auto& files = plc.files();
    if (!files.cassette_mounted()) return EndCode::file_device_missing;

    switch (op) {
        case CassetteOperation::read_type: {
            std::uint16_t stored = 0;
            for (const auto& item : items) {
                const auto content = files.cassette_item(item.file);
                if (!content) return to_end_code(content.error());
                if (*content) stored = static_cast<std::uint16_t>(stored | item.bit);
            }
            out.u16(stored);
            return EndCode::normal_completion;
        }
        case CassetteOperation::initialize:
            return files.initialize_cassette();
        case CassetteOperation::save: {
            if ((areas & cassette_program) != 0 && plc.dip_write_protection())
                return EndCode::read_only;
            const auto now = plc.clock().civil(context.request.now);
            for (const auto& item : items) {
                if ((areas & item.bit) == 0) continue;
                if (const auto code =
                        files.store_cassette_item(item.file, snapshot(plc, item.bit), now);
                    code != EndCode::normal_completion)
                    return code;
            }
            return EndCode::normal_completion;
        }
        case CassetteOperation::load:
        case CassetteOperation::verify:
            break;
    }
    const bool all = (command.designation & cassette_individual) == 0;
    const auto loaded = gather(plc, areas, all);
    if (!loaded) return to_end_code(loaded.error());
    if (op == CassetteOperation::load) {
        const bool program = std::any_of(loaded->begin(), loaded->end(), [](const auto& item) {
            return item.first == cassette_program;
        });
        if (program && plc.dip_write_protection()) return EndCode::read_only;
        for (const auto& [bit, file] : *loaded)
            restore(plc, bit, file);
        return EndCode::normal_completion;
    }
    for (const auto& [bit, file] : *loaded)
        if (snapshot(plc, bit) != file) return EndCode::data_mismatch;
    return EndCode::normal_completion;
}

}  // namespace fins::server::handlers
