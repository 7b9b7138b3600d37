// `fins files cassette` for 22 20 MEMORY CASSETTE TRANSFER (W342 5-3-43; the CP1H's
// Memory Cassette, disk 8003; docs/file-memory.md "Memory Cassette (22 20, CP1H)"):
//   files cassette save   [AREA...]   0000 CPU Unit -> cassette
//   files cassette load   [AREA...]   0001 cassette -> CPU Unit (PROGRAM mode)
//   files cassette verify [AREA...]   0002 compare (exit 4 with 2007 on a difference)
//   files cassette init               0003 erase the cassette
//   files cassette type               8000 which data types the cassette holds
// AREA: program, parameters, dm, symbols, comments, indices, dm-init; none = all areas
// (designation bit 15 OFF). Exit codes as every verb: 0, 2, 3, 4.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "fins/commands/memory_cassette.hpp"

namespace fins::cli {

void add_cassette_verbs(CLI::App& files, const GlobalOptions& g, int& exit_code);

namespace {

struct AreaName {
    std::string_view name;
    std::uint16_t bit;
};

// Stored data type bits 07-00 (5-3-43 "Stored data type (response)"); the designation
// uses the same bits except 01 (reserved there: FB sources travel with the program).
constexpr AreaName areas[] = {{"program", cassette_program},
                              {"fb-sources", cassette_fb_sources},
                              {"parameters", cassette_parameters},
                              {"symbols", cassette_symbol_table},
                              {"comments", cassette_comments},
                              {"indices", cassette_program_indices},
                              {"dm", cassette_dm},
                              {"dm-init", cassette_dm_initial_values}};

struct CassetteArgs {
    std::vector<std::string> areas;
};

int run(const GlobalOptions& g, const CassetteArgs& a, CassetteOperation op, Output& out) {
    std::uint16_t designation = 0;
    for (const auto& text : a.areas) {
        const AreaName* found = nullptr;
        for (const auto& area : areas)
            if (area.name == text && area.bit != cassette_fb_sources) found = &area;
        if (found == nullptr)
            return out.usage(fmt::format(
                "'{}' is not a cassette area (program, parameters, dm, symbols, comments, "
                "indices, dm-init)",
                text));
        designation = static_cast<std::uint16_t>(designation | cassette_individual | found->bit);
    }
    const char* verb = "files cassette";
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    const auto r = client->send(
        MemoryCassetteTransfer{disk_memory_cassette, static_cast<std::uint16_t>(op), designation});
    if (!r) return out.failure(r.error(), verb);
    if (op != CassetteOperation::read_type) {
        out.print({{"ok", true}}, "files cassette: done\n");
        return exit_ok;
    }
    nlohmann::json held = nlohmann::json::array();
    std::string text;
    for (const auto& area : areas) {
        if ((r->stored & area.bit) == 0) continue;
        held.push_back(std::string(area.name));
        text += fmt::format("{}{}", text.empty() ? "" : " ", area.name);
    }
    out.print({{"stored", held}, {"bits", fmt::format("{:04X}", r->stored)}},
              (text.empty() ? std::string("(empty)") : text) + "\n");
    return exit_ok;
}

}  // namespace

void add_cassette_verbs(CLI::App& files, const GlobalOptions& g, int& exit_code) {
    auto* cassette =
        files.add_subcommand("cassette", "CP1H Memory Cassette (22 20): save, load, verify ...");
    cassette->require_subcommand(1);
    struct {
        const char* name;
        const char* help;
        CassetteOperation op;
    } verbs[] = {
        {"save", "CPU Unit -> Memory Cassette (all areas, or the AREAs named)",
         CassetteOperation::save},
        {"load", "Memory Cassette -> CPU Unit (PROGRAM mode)", CassetteOperation::load},
        {"verify", "Compare the CPU Unit with the Memory Cassette", CassetteOperation::verify},
        {"init", "Erase the Memory Cassette", CassetteOperation::initialize},
        {"type", "Which data types the Memory Cassette holds", CassetteOperation::read_type},
    };
    for (const auto& v : verbs) {
        auto args = std::make_shared<CassetteArgs>();
        auto* c = cassette->add_subcommand(v.name, v.help);
        const auto op = v.op;
        c->callback([&g, &exit_code, args, op] {
            Output out{g.json};
            exit_code = run(g, *args, op, out);
        });
        if (op != CassetteOperation::initialize && op != CassetteOperation::read_type)
            c->add_option("areas", args->areas,
                          "program, parameters, dm, symbols, comments, indices, dm-init "
                          "(default: all)");
    }
}

}  // namespace fins::cli
