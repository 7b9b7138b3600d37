// What `fins` says when the verb is missing or misspelt: CLI11 only knows "A subcommand
// is required" (issue 18 item 8). The nearest verbs by edit distance are suggested, and a
// verb group typed alone (`fins files`) lists its sub-verbs.
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "cli/fins/commands.hpp"

namespace fins::cli {

namespace {

// Levenshtein distance with adjacent transpositions counted as one edit ("raed" -> "read").
std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> before(b.size() + 1), previous(b.size() + 1), current(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j)
        previous[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        current[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t substitute = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitute});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                current[j] = std::min(current[j], before[j - 2] + 1);
        }
        before = previous;
        previous = current;
    }
    return previous[b.size()];
}

// "fins" or "fins files" or "fins files cassette".
std::string command_path(CLI::App* app) {
    std::string path;
    for (CLI::App* a = app; a != nullptr; a = a->get_parent())
        path = (a->get_parent() == nullptr ? std::string("fins") : a->get_name()) +
               (path.empty() ? "" : " " + path);
    return path;
}

std::string join(const std::vector<std::string>& names) {
    std::string text;
    for (const auto& n : names)
        text += (text.empty() ? "" : ", ") + n;
    return text;
}

}  // namespace

std::optional<std::string> explain_missing_verb(CLI::App& app) {
    // The deepest verb the command line named, e.g. `files` in `fins files lsit`.
    CLI::App* group = &app;
    for (auto parsed = group->get_subcommands(); !parsed.empty(); parsed = group->get_subcommands())
        group = parsed.front();
    if (group->get_require_subcommand_min() == 0) return std::nullopt;

    std::vector<std::string> verbs;
    for (const CLI::App* sub : group->get_subcommands({}))
        verbs.push_back(sub->get_name());
    // What was typed where the verb belongs: the first word nobody took. Positionals a
    // group does not take fall through to its parents.
    std::string typed;
    for (CLI::App* a = group; a != nullptr && typed.empty(); a = a->get_parent())
        for (const auto& word : a->remaining(false))
            if (!word.empty() && word.front() != '-') {
                typed = word;
                break;
            }
    const std::string where = command_path(group);
    if (typed.empty())
        return fmt::format("'{}' needs a verb: {} (see {} --help)", where, join(verbs), where);

    // Suggest the verbs within a third of the typed length (at least 1, at most 3 edits),
    // nearest first; a verb that starts with what was typed counts too (`fins cpu`).
    const std::size_t limit = std::clamp<std::size_t>(typed.size() / 3, 1, 3);
    std::vector<std::pair<std::size_t, std::string>> near;
    for (const auto& v : verbs) {
        const auto d = edit_distance(typed, v);
        if (d <= limit || (typed.size() >= 3 && v.rfind(typed, 0) == 0)) near.emplace_back(d, v);
    }
    std::stable_sort(near.begin(), near.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    std::string message = fmt::format("unknown verb '{}'", typed);
    if (group != &app) message = fmt::format("'{}' has no verb '{}'", where, typed);
    if (!near.empty()) {
        std::vector<std::string> names;
        for (const auto& [d, v] : near)
            names.push_back(v);
        message += fmt::format(": did you mean {}?", join(names));
    } else {
        message += fmt::format("; the verbs are: {}", join(verbs));
    }
    return message + fmt::format(" (see {} --help)", where);
}

}  // namespace fins::cli
