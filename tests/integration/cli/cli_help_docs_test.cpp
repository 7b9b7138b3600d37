// What the programs say about themselves agrees with the documentation (issue 26 point 13):
// no --help text of fins, finsd or fins-bridge sends a reader to README sections that
// moved to docs/; docs/finsd.md's synopsis names every option `finsd --help` prints; the
// man pages made from --help and packaging/man/*.h2m (as cmake/FinsDebian.cmake makes
// them) have EXIT STATUS and EXAMPLES; the bash completion completes fins-bridge's options.
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"
#include "integration/support/process.hpp"

namespace fins::test {
namespace {

const std::string bin_dir = FINS_BIN_DIR;
const std::filesystem::path source_dir = FINS_SOURCE_DIR;

std::string file_text(const std::filesystem::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// The words of the "Subcommands:" section of a CLI11 help text.
std::vector<std::string> subcommands(const std::string& help) {
    std::vector<std::string> out;
    std::istringstream in(help);
    bool inside = false;
    for (std::string line; std::getline(in, line);) {
        if (!line.empty() && line[0] != ' ')
            inside = line == "Subcommands:";
        else if (inside && line.size() > 2 && line[2] >= 'a' && line[2] <= 'z')
            out.push_back(line.substr(2, line.find(' ', 2) - 2));
    }
    return out;
}

// The long options of a CLI11 help text ("--udp,--no-udp{false}" gives both).
std::set<std::string> long_options(const std::string& help) {
    std::set<std::string> out;
    const std::regex option(R"(--[a-z][a-z0-9-]*)");
    std::istringstream in(help);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("  -", 0) != 0) continue;
        const std::string names = line.substr(2, line.find(' ', 2) - 2);
        for (std::sregex_iterator i(names.begin(), names.end(), option), end; i != end; ++i)
            out.insert(i->str());
    }
    return out;
}

// Every help text a user can ask for: each program, each verb and group of fins, finsd ctl.
std::vector<std::pair<std::string, std::string>> every_help() {
    std::vector<std::pair<std::string, std::string>> helps;
    const auto add = [&helps](std::vector<std::string> argv) {
        std::string name;
        for (const auto& a : argv)
            name += (name.empty() ? "" : " ") + std::filesystem::path(a).filename().string();
        argv.push_back("--help");
        const auto r = run(argv);
        EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
        helps.emplace_back(name, r.out + r.err);
    };
    const std::string fins = bin_dir + "/fins";
    add({fins});
    for (const auto& verb : subcommands(helps.back().second)) {
        add({fins, verb});
        for (const auto& sub : subcommands(helps.back().second))
            add({fins, verb, sub});
    }
    add({bin_dir + "/finsd"});
    add({bin_dir + "/finsd", "ctl"});
    add({bin_dir + "/fins-bridge"});
    return helps;
}

TEST(HelpTexts, NoHelpTextSendsTheReaderToTheReadme) {
    const auto helps = every_help();
    EXPECT_GT(helps.size(), 40u);  // fins' verbs and groups, finsd, finsd ctl, fins-bridge
    for (const auto& [name, text] : helps)
        EXPECT_EQ(text.find("README"), std::string::npos) << name << " --help:\n" << text;
}

TEST(HelpTexts, TheDocsPagesTheHelpTextsNameExist) {
    const std::regex page(R"(docs/[a-z0-9-]+\.md)");
    std::size_t named = 0;
    for (const auto& [name, text] : every_help())
        for (std::sregex_iterator i(text.begin(), text.end(), page), end; i != end; ++i, ++named)
            EXPECT_TRUE(std::filesystem::exists(source_dir / i->str())) << name << ": " << i->str();
    EXPECT_GT(named, 0u);
}

// The synopsis: the first code block of docs/finsd.md.
TEST(FinsdDoc, SynopsisNamesEveryOptionOfFinsdHelp) {
    const auto page = file_text(source_dir / "docs/finsd.md");
    const auto open = page.find("```\nfinsd ");
    ASSERT_NE(open, std::string::npos);
    const auto synopsis = page.substr(open, page.find("```", open + 3) - open);
    const auto help = run({finsd_path, "--help"});
    ASSERT_EQ(help.exit_code, 0);
    const auto options = long_options(help.out);
    EXPECT_GT(options.size(), 25u) << help.out;
    const std::regex named(R"(--[a-z][a-z0-9-]*)");
    std::set<std::string> in_synopsis;
    for (std::sregex_iterator i(synopsis.begin(), synopsis.end(), named), end; i != end; ++i)
        in_synopsis.insert(i->str());
    for (const auto& option : options)
        EXPECT_TRUE(in_synopsis.count(option)) << option << " is not in docs/finsd.md's synopsis";
}

// As cmake/FinsDebian.cmake makes them (help2man from PATH, the .h2m included).
TEST(ManPages, EachProgramsPageHasExitStatusExamplesAndSeeAlso) {
    if (!std::filesystem::exists("/usr/bin/help2man")) GTEST_SKIP() << "help2man not installed";
    ScratchDir dir("man");
    for (const auto& [program, section] :
         {std::pair<std::string, std::string>{"fins", "1"}, {"finsd", "8"}, {"fins-bridge", "8"}}) {
        const auto out = (dir.path() / (program + "." + section)).string();
        const auto r =
            run({"/usr/bin/env", "PATH=" + bin_dir + ":/usr/bin:/bin", "/usr/bin/help2man",
                 "--no-info", "--section", section, "--version-option=--version", "--include",
                 (source_dir / "packaging/man" / (program + ".h2m")).string(), "--output", out,
                 program});
        ASSERT_EQ(r.exit_code, 0) << program << ": " << r.err;
        const auto page = file_text(out);
        for (const char* heading :
             {".SH OPTIONS", ".SH \"EXIT STATUS\"", ".SH EXAMPLES", ".SH \"SEE ALSO\""})
            EXPECT_NE(page.find(std::string("\n") + heading + "\n"), std::string::npos)
                << program << "(" << section << ") lacks " << heading;
        EXPECT_EQ(page.find("README"), std::string::npos) << program;
    }
}

// The completion reads the options from `fins-bridge --help` at each Tab.
TEST(Completion, FinsBridgeOptionsAndLogLevelsComplete) {
    const auto script = (source_dir / "packaging/completions/finskit.bash").string();
    const auto complete = [&script](const std::string& words) {
        const std::string body = "source '" + script + "'; COMP_WORDS=(" + words +
                                 "); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); _finskit_complete; "
                                 "printf '%s\\n' \"${COMPREPLY[@]}\"";
        return run({"/usr/bin/env", "PATH=" + bin_dir + ":/usr/bin:/bin", "bash", "-c", body});
    };
    const auto help = run({bin_dir + "/fins-bridge", "--help"});
    const auto options = long_options(help.out);
    ASSERT_TRUE(options.count("--config")) << help.out;
    for (const auto& option : options) {
        const auto r = complete("fins-bridge " + option.substr(0, 4));
        EXPECT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(("\n" + r.out).find("\n" + option + "\n"), std::string::npos)
            << option << ": " << r.out;
    }
    EXPECT_EQ(complete("fins-bridge --log-level w").out, "warn\n");
    const auto registered =
        run({"/bin/bash", "-c", "source '" + script + "'; complete -p fins-bridge"});
    EXPECT_NE(registered.out.find("_finskit_complete"), std::string::npos) << registered.err;
}

}  // namespace
}  // namespace fins::test
