// The documentation's sample sessions are what the programs print today, and its links
// lead somewhere.
//
// Pages: README.md and every docs/*.md, one test each (a failure names the page).
// Checked: every fenced block with at least one line starting with "$ ". Such a block
// is a session against a finsd started for it alone (port 0, a control socket, a
// scratch working directory); an HTML comment on the line before the fence adds finsd
// flags:   <!-- readme-test: finsd --profile cs1h-lcb -->  ("{source}": the source tree)
// In the block:
//   "$ fins ARGS"       runs build/bin/fins with --port of that finsd added
//   "$ finsd ctl ARGS"  runs finsd ctl as shown (both find the default socket)
//   "  # text"          after a command is a comment (not passed)
//   other lines         the expected output: stdout, then stderr, line by line; none
//                       means none. A line "..." stands for any number of lines, and
//                       "..." inside a line for any text (clock, cycle times).
// Blocks without "$ " lines (shell recipes, TOML, C++) are not run.
// Links: every relative link outside code blocks names an existing file, and its #anchor
// a heading of that page (GitHub's rule: lower case, punctuation dropped, blanks to '-').
#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
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

const std::filesystem::path source_dir = FINS_SOURCE_DIR;
const std::string fins_bin = std::string(FINS_BIN_DIR) + "/fins";
constexpr std::string_view wildcard = "...";
constexpr std::string_view marker = "<!-- readme-test: finsd";

struct Step {
    int line = 0;
    std::string command;
    std::vector<std::string> expected;
};
struct Block {
    int line = 0;
    std::vector<std::string> finsd_args;
    std::vector<Step> steps;
};

// Shell-like words: blanks separate, '...' and "..." quote, an unquoted " #" starts a comment.
std::vector<std::string> split_words(const std::string& text) {
    std::vector<std::string> words;
    std::string word;
    bool in_word = false;
    char quote = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quote != 0) {
            if (c == quote)
                quote = 0;
            else
                word += c;
        } else if (c == '\'' || c == '"') {
            quote = c;
            in_word = true;
        } else if (c == ' ' || c == '\t') {
            if (in_word) words.push_back(word);
            word.clear();
            in_word = false;
        } else if (c == '#' && !in_word) {
            break;
        } else {
            word += c;
            in_word = true;
        }
    }
    if (in_word) words.push_back(word);
    return words;
}

std::vector<Block> checked_blocks(const std::string& path) {
    std::ifstream f(path);
    std::vector<Block> blocks;
    std::string line;
    std::string previous;
    int number = 0;
    std::optional<Block> open;
    while (std::getline(f, line)) {
        ++number;
        if (line.rfind("```", 0) == 0) {
            if (!open) {
                open = Block{};
                open->line = number;
                if (const auto at = previous.find(marker); at != std::string::npos) {
                    auto args = previous.substr(at + marker.size());
                    args = args.substr(0, args.find("-->"));
                    open->finsd_args = split_words(args);
                }
            } else {
                if (!open->steps.empty()) blocks.push_back(*open);
                open.reset();
            }
        } else if (open) {
            if (line.rfind("$ ", 0) == 0)
                open->steps.push_back(Step{number, line.substr(2), {}});
            else if (!open->steps.empty())
                open->steps.back().expected.push_back(line);
        }
        if (!line.empty()) previous = line;
    }
    return blocks;
}

bool line_matches(std::string_view pattern, std::string_view text) {
    const auto star = pattern.find(wildcard);
    if (star == std::string_view::npos) return pattern == text;
    const auto head = pattern.substr(0, star);
    if (text.substr(0, head.size()) != head) return false;
    const auto rest = pattern.substr(star + wildcard.size());
    for (std::size_t i = head.size(); i <= text.size(); ++i)
        if (line_matches(rest, text.substr(i))) return true;
    return false;
}

bool lines_match(const std::vector<std::string>& pattern, std::size_t p,
                 const std::vector<std::string>& text, std::size_t t) {
    if (p == pattern.size()) return t == text.size();
    if (pattern[p] == wildcard) {
        for (std::size_t k = t; k <= text.size(); ++k)
            if (lines_match(pattern, p + 1, text, k)) return true;
        return false;
    }
    return t < text.size() && line_matches(pattern[p], text[t]) &&
           lines_match(pattern, p + 1, text, t + 1);
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line))
        lines.push_back(line);
    return lines;
}

std::string joined(const std::vector<std::string>& lines) {
    std::string s;
    for (const auto& l : lines)
        s += "    " + l + "\n";
    return s;
}

TEST(Readme, ParsesItsOwnRules) {
    EXPECT_EQ(split_words("fins clock --set \"2030-01-02 03:04:05\"  # comment"),
              (std::vector<std::string>{"fins", "clock", "--set", "2030-01-02 03:04:05"}));
    EXPECT_TRUE(line_matches("average ... ms", "average 3.0 ms"));
    EXPECT_FALSE(line_matches("average ... ms", "average 3.0 s"));
    EXPECT_TRUE(lines_match({"a", "...", "d"}, 0, {"a", "b", "c", "d"}, 0));
    EXPECT_TRUE(lines_match({"a", "..."}, 0, {"a"}, 0));
    EXPECT_FALSE(lines_match({"a"}, 0, {"a", "b"}, 0));
    EXPECT_FALSE(lines_match({}, 0, {"unexpected"}, 0));
}

// README.md and docs/*.md, as paths relative to the source tree.
std::vector<std::string> doc_pages() {
    std::vector<std::string> pages{"README.md"};
    for (const auto& entry : std::filesystem::directory_iterator(source_dir / "docs"))
        if (entry.is_regular_file() && entry.path().extension() == ".md")
            pages.push_back("docs/" + entry.path().filename().string());
    std::sort(pages.begin() + 1, pages.end());
    return pages;
}

// GitHub's anchor for a heading.
std::string slug(std::string_view heading) {
    std::string s;
    for (const char c : heading) {
        const auto u = static_cast<unsigned char>(c);
        if (std::isalnum(u) || c == '_' || c == '-')
            s += static_cast<char>(std::tolower(u));
        else if (c == ' ')
            s += '-';
    }
    return s;
}

// XDG_RUNTIME_DIR set to `dir` and FINSD_SOCKET unset while it lives (children inherit
// them: the finsd of a block and its finsd ctl steps); the values before come back after.
class RuntimeDirectory {
  public:
    explicit RuntimeDirectory(const std::filesystem::path& dir)
        : xdg_(saved("XDG_RUNTIME_DIR")), socket_(saved("FINSD_SOCKET")) {
        ::setenv("XDG_RUNTIME_DIR", dir.c_str(), 1);
        ::unsetenv("FINSD_SOCKET");
    }
    ~RuntimeDirectory() {
        restore("XDG_RUNTIME_DIR", xdg_);
        restore("FINSD_SOCKET", socket_);
    }
    RuntimeDirectory(const RuntimeDirectory&) = delete;
    RuntimeDirectory& operator=(const RuntimeDirectory&) = delete;

  private:
    static std::optional<std::string> saved(const char* name) {
        const char* v = std::getenv(name);
        return v != nullptr ? std::optional<std::string>(v) : std::nullopt;
    }
    static void restore(const char* name, const std::optional<std::string>& value) {
        if (value)
            ::setenv(name, value->c_str(), 1);
        else
            ::unsetenv(name);
    }
    std::optional<std::string> xdg_;
    std::optional<std::string> socket_;
};

struct PageText {
    std::set<std::string> anchors;
    std::vector<std::pair<int, std::string>> links;  // line, url
};

PageText read_page(const std::filesystem::path& path) {
    std::ifstream f(path);
    PageText page;
    static const std::regex link(R"(\[[^\]]*\]\(([^)\s]+)\))");
    std::string line;
    bool fence = false;
    int number = 0;
    while (std::getline(f, line)) {
        ++number;
        if (line.rfind("```", 0) == 0) fence = !fence;
        if (fence) continue;
        if (const auto hashes = line.find_first_not_of('#');
            hashes > 0 && hashes != std::string::npos && line[hashes] == ' ')
            page.anchors.insert(slug(line.substr(hashes + 1)));
        for (std::sregex_iterator it(line.begin(), line.end(), link), end; it != end; ++it)
            page.links.emplace_back(number, (*it)[1].str());
    }
    return page;
}

std::string test_name(const testing::TestParamInfo<std::string>& info) {
    std::string name;
    for (const char c : info.param)
        if (std::isalnum(static_cast<unsigned char>(c))) name += c;
    return name;
}

class Doc : public testing::TestWithParam<std::string> {};

TEST(Doc, EveryPageIsFoundAndTheSessionsAreMany) {
    const auto pages = doc_pages();
    EXPECT_GE(pages.size(), 9u) << "README.md and the docs/ pages";
    std::size_t blocks = 0;
    for (const auto& page : pages)
        blocks += checked_blocks((source_dir / page).string()).size();
    EXPECT_GE(blocks, 6u) << "sample sessions found in all pages";
    EXPECT_EQ(slug("FINS/TCP identity and limits"), "finstcp-identity-and-limits");
    EXPECT_EQ(slug("The `fins` CLI"), "the-fins-cli");
}

TEST_P(Doc, EveryLinkLeadsToAFileAndAHeading) {
    const auto here = source_dir / GetParam();
    const auto page = read_page(here);
    for (const auto& [line, url] : page.links) {
        if (url.find("://") != std::string::npos || url.rfind("mailto:", 0) == 0) continue;
        const auto hash = url.find('#');
        const auto file = url.substr(0, hash);
        const auto target = file.empty() ? here : here.parent_path() / file;
        EXPECT_TRUE(std::filesystem::exists(target))
            << GetParam() << ":" << line << ": " << url << " names no file";
        if (hash == std::string::npos || target.extension() != ".md" ||
            !std::filesystem::exists(target))
            continue;
        EXPECT_EQ(read_page(target).anchors.count(url.substr(hash + 1)), 1u)
            << GetParam() << ":" << line << ": " << url << " names no heading";
    }
}

TEST_P(Doc, EverySampleSessionPrintsWhatThePageShows) {
    const auto& name = GetParam();
    const auto blocks = checked_blocks((source_dir / name).string());
    if (name == "README.md") {
        ASSERT_GE(blocks.size(), 1u) << "the README's tour is gone";
    }
    const auto home = std::filesystem::current_path();
    for (const auto& block : blocks) {
        SCOPED_TRACE(name + ":" + std::to_string(block.line));
        ScratchDir dir("readme");
        // finsd and finsd ctl run as the docs show them, without --control/--socket: they
        // meet at $XDG_RUNTIME_DIR/finsd.sock, a scratch directory of this block's own.
        const RuntimeDirectory runtime(dir.path());
        auto args = block.finsd_args;
        // "{source}" in a flag is the source tree (an example file: docs/scenarios.md).
        for (auto& arg : args)
            if (const auto at = arg.find("{source}"); at != std::string::npos)
                arg.replace(at, 8, source_dir.string());
        Finsd finsd(args);
        ASSERT_TRUE(finsd.started()) << finsd.result().err;
        // Files a session writes (program-read --out) land in the scratch directory.
        std::filesystem::current_path(dir.path());
        for (const auto& step : block.steps) {
            const auto words = split_words(step.command);
            std::vector<std::string> argv;
            if (!words.empty() && words[0] == "fins") {
                argv = {fins_bin, "--port", std::to_string(finsd.port()), "--timeout", "5"};
            } else if (words.size() > 1 && words[0] == "finsd" && words[1] == "ctl") {
                argv = {finsd_path};
                argv.insert(argv.end(), words.begin() + 1, words.end());
            }
            ASSERT_FALSE(argv.empty())
                << name << ":" << step.line
                << ": only fins and finsd ctl run in a session: " << step.command;
            if (words[0] == "fins") argv.insert(argv.end(), words.begin() + 1, words.end());
            const auto r = run(argv);
            const auto actual = lines_of(r.out + r.err);
            EXPECT_TRUE(lines_match(step.expected, 0, actual, 0))
                << name << ":" << step.line << ": $ " << step.command << "\n"
                << name << " shows:\n"
                << joined(step.expected) << "the program printed (exit " << r.exit_code << "):\n"
                << joined(actual);
        }
        std::filesystem::current_path(home);
    }
}

INSTANTIATE_TEST_SUITE_P(Pages, Doc, testing::ValuesIn(doc_pages()), test_name);

}  // namespace
}  // namespace fins::test
