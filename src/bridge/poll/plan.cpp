#include "bridge/poll/plan.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "fins/commands/memory_area.hpp"

namespace fins::bridge {

namespace {

struct Run {
    std::uint8_t code = 0;
    std::uint32_t first = 0;
    std::uint32_t end = 0;  // one past the last word
    std::vector<std::size_t> tags;
};

MemoryAddress word_at(std::uint8_t code, std::uint32_t word) {
    return {code, static_cast<std::uint16_t>(word), 0};
}

}  // namespace

Plan plan_group(std::span<const Tag> tags, std::size_t gap_words) {
    Plan plan;
    plan.slots.resize(tags.size());

    // Word tags sorted by (area code, first word); flags go straight to 01 04.
    std::vector<std::size_t> order;
    std::vector<std::size_t> scattered;
    for (std::size_t i = 0; i < tags.size(); ++i)
        (tags[i].flag ? scattered : order).push_back(i);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const auto& x = tags[a].read_start;
        const auto& y = tags[b].read_start;
        return x.area_code != y.area_code ? x.area_code < y.area_code : x.word < y.word;
    });

    std::vector<Run> runs;
    for (std::size_t i : order) {
        const Tag& t = tags[i];
        const std::uint32_t first = t.read_start.word;
        const std::uint32_t end = first + static_cast<std::uint32_t>(t.words);
        if (!runs.empty()) {
            Run& r = runs.back();
            const bool same_area = r.code == t.read_start.area_code;
            const bool near = first <= r.end + gap_words;
            const std::uint32_t new_end = std::max(r.end, end);
            if (same_area && near && new_end - r.first <= max_read_words) {
                r.end = new_end;
                r.tags.push_back(i);
                continue;
            }
        }
        runs.push_back({t.read_start.area_code, first, end, {i}});
    }

    // A run of one tag of at most two words is a scattered point, and so is a run of one
    // word (the bits of one word: CIO0.00-0.15) and every flag: they share 01 04 frames
    // instead of taking a frame each.
    struct Point {
        MemoryAddress start;      // a flag: its element
        std::uint32_t words = 0;  // 0: a flag (one element)
        std::vector<std::size_t> tags;
    };
    std::vector<Point> points;
    for (std::size_t i : scattered)
        points.push_back({tags[i].read_start, 0, {i}});
    for (auto& r : runs) {
        if ((r.tags.size() == 1 && r.end - r.first <= 2) || r.end - r.first == 1) {
            points.push_back({word_at(r.code, r.first), r.end - r.first, r.tags});
            continue;
        }
        PlannedFrame f;
        f.kind = PlannedFrame::Kind::read;
        f.start = word_at(r.code, r.first);
        f.count = static_cast<std::uint16_t>(r.end - r.first);
        f.tags = r.tags;
        const auto index = static_cast<std::uint16_t>(plan.frames.size());
        for (std::size_t i : r.tags)
            plan.slots[i] = {index, static_cast<std::uint16_t>(tags[i].read_start.word - r.first)};
        plan.frames.push_back(std::move(f));
    }

    // Scattered points in file order (of their first tag), packed 167 elements a frame.
    std::sort(points.begin(), points.end(), [](const Point& x, const Point& y) {
        return *std::min_element(x.tags.begin(), x.tags.end()) <
               *std::min_element(y.tags.begin(), y.tags.end());
    });
    std::size_t at = 0;
    while (at < points.size()) {
        PlannedFrame f;
        f.kind = PlannedFrame::Kind::multiple_read;
        const auto index = static_cast<std::uint16_t>(plan.frames.size());
        std::size_t in_frame = 0;
        while (at < points.size()) {
            const Point& p = points[at];
            const std::size_t n = p.words == 0 ? 1 : p.words;
            if (f.items.size() + n > max_multiple_read_elements) break;
            for (std::size_t i : p.tags)
                plan.slots[i] = {index,
                                 static_cast<std::uint16_t>(
                                     f.items.size() + tags[i].read_start.word -
                                     (p.words == 0 ? tags[i].read_start.word : p.start.word))};
            if (p.words == 0) f.items.push_back(p.start);
            for (std::uint32_t k = 0; k < p.words; ++k)
                f.items.push_back(word_at(p.start.area_code, p.start.word + k));
            f.tags.insert(f.tags.end(), p.tags.begin(), p.tags.end());
            ++at;
            ++in_frame;
        }
        if (in_frame == 1 && points[at - 1].words != 0) {
            // One word point: a plain read says the same in a shorter answer.
            const Point& p = points[at - 1];
            f.kind = PlannedFrame::Kind::read;
            f.start = p.start;
            f.count = static_cast<std::uint16_t>(p.words);
            f.items.clear();
            for (std::size_t i : p.tags)
                plan.slots[i] = {
                    index, static_cast<std::uint16_t>(tags[i].read_start.word - p.start.word)};
        }
        plan.frames.push_back(std::move(f));
    }
    return plan;
}

std::string describe_plan(const Plan& plan, std::span<const Tag> tags) {
    std::string out;
    auto it = std::back_inserter(out);
    for (const auto& f : plan.frames) {
        if (f.kind == PlannedFrame::Kind::read) {
            const Tag& first = tags[f.tags.front()];
            Address a = first.address;
            a.bit.reset();
            a.word = f.start.word;
            fmt::format_to(it, "01 01 {} x {} words ({:02X} {:04X}):", format_address(a), f.count,
                           f.start.area_code, f.start.word);
        } else {
            fmt::format_to(it, "01 04 {} elements:", f.items.size());
        }
        for (std::size_t i : f.tags)
            fmt::format_to(it, " {}={}", tags[i].name, tags[i].address_text);
        out += '\n';
    }
    return out;
}

}  // namespace fins::bridge
