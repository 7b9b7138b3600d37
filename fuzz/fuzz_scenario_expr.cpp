// Fuzzes the scenario expression parser and evaluator (src/scenario/expression.hpp): any
// text either parses or fails with a position inside it; what parses evaluates (with
// references, random draws and the time) to a number without crashing, and never reads
// a reference it did not report.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "scenario/expression.hpp"

namespace {

void check(bool ok) {
    if (!ok) __builtin_trap();
}

struct Context final : fins::scenario::ExpressionContext {
    const fins::scenario::Expression* expression = nullptr;
    double load(std::uint32_t reference) noexcept override {
        bool known = false;
        for (auto r : expression->references())
            known = known || r == reference;
        check(known);
        return static_cast<double>(reference) - 3.5;
    }
    double normal() noexcept override { return 0.25; }
    double uniform() noexcept override { return 0.75; }
    double time() const noexcept override { return 12.5; }
    double tick() const noexcept override { return 0.1; }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace fins;
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    scenario::ExpressionError error;
    auto resolve = [](const Address& a, std::string& message) -> std::optional<std::uint32_t> {
        if (a.area == Area::em) {
            message = "no EM here";
            return std::nullopt;
        }
        return static_cast<std::uint32_t>(a.word) + (a.bit ? 100000u : 0u);
    };
    auto parsed = scenario::Expression::parse(text, resolve, error);
    if (!parsed) {
        check(!error.message.empty() && error.line >= 1 && error.column >= 1);
        check(error.line <= size + 1 && error.column <= size + 1);
        return 0;
    }
    Context context;
    context.expression = &*parsed;
    const double v = parsed->evaluate(context);
    (void)v;
    return 0;
}
