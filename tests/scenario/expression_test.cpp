// The scenario expression language: precedence, functions, references, errors with
// line:col, bounds.
#include "scenario/expression.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace fins::scenario {
namespace {

struct Context final : ExpressionContext {
    std::map<std::uint32_t, double> values;
    double load(std::uint32_t r) noexcept override { return values[r]; }
    double normal() noexcept override { return 2.0; }
    double uniform() noexcept override { return 0.5; }
    double time() const noexcept override { return 7.0; }
    double tick() const noexcept override { return 0.1; }
};

// Resolves every address to a number of its own: D100 -> 100, CIO0.01 -> 10001.
std::optional<std::uint32_t> resolve(const Address& a, std::string& message) {
    if (a.area == Area::em && a.bank > 3) {
        message = "no such bank";
        return std::nullopt;
    }
    return static_cast<std::uint32_t>(a.word + (a.bit ? 10000u + *a.bit : 0u));
}

double eval(std::string_view text, Context& context) {
    ExpressionError e;
    auto x = Expression::parse(text, resolve, e);
    EXPECT_TRUE(x.has_value()) << text << ": " << e.line << ":" << e.column << " " << e.message;
    return x ? x->evaluate(context) : std::nan("");
}

double eval(std::string_view text) {
    Context c;
    return eval(text, c);
}

ExpressionError fails(std::string_view text) {
    ExpressionError e;
    EXPECT_FALSE(Expression::parse(text, resolve, e).has_value()) << text;
    return e;
}

TEST(ScenarioExpression, ArithmeticFollowsPrecedence) {
    EXPECT_DOUBLE_EQ(eval("1 + 2 * 3"), 7);
    EXPECT_DOUBLE_EQ(eval("(1 + 2) * 3"), 9);
    EXPECT_DOUBLE_EQ(eval("2 ^ 3 ^ 2"), 512);  // right-associative
    EXPECT_DOUBLE_EQ(eval("-2 ^ 2"), -4);
    EXPECT_DOUBLE_EQ(eval("7 % 4 - 10 / 4"), 0.5);
    EXPECT_DOUBLE_EQ(eval("0x1F + 1e1 + .5"), 41.5);
}

// A number right before + - * / or noise is one instruction with it (the same results,
// left to right, and the same random draws).
TEST(ScenarioExpression, ANumberAndTheOperatorAfterItAreOneInstruction) {
    ExpressionError e;
    auto x = Expression::parse("D100 / 20 + 400 - noise(2) * 3", resolve, e);
    ASSERT_TRUE(x.has_value());
    // load, divide_number, add_number, noise_number, multiply_number, subtract
    EXPECT_EQ(x->program().size(), 6u);
    Context c;
    c.values[100] = 3000;
    EXPECT_DOUBLE_EQ(x->evaluate(c), 3000.0 / 20 + 400 - 2.0 * 2 * 3);
    EXPECT_DOUBLE_EQ(eval("1 - 2 - 3"), -4);
    EXPECT_DOUBLE_EQ(eval("64 / 4 / 2"), 8);
    EXPECT_DOUBLE_EQ(eval("2 - (3 - 4)"), 3);
    EXPECT_DOUBLE_EQ(eval("2 * -3"), -6);  // negate in between: not fused
    EXPECT_DOUBLE_EQ(eval("10 - 2 ^ 2"), 6);
    EXPECT_TRUE(std::isinf(eval("1 / 0")));
}

TEST(ScenarioExpression, ComparisonsAndLogicGiveOneOrZero) {
    EXPECT_EQ(eval("1 < 2 && 3 >= 3"), 1);
    EXPECT_EQ(eval("1 == 2 || 2 != 2"), 0);
    EXPECT_EQ(eval("!0 + !5"), 1);
    EXPECT_EQ(eval("1 + 1 == 2"), 1);
}

TEST(ScenarioExpression, Functions) {
    EXPECT_EQ(eval("min(4, 2, 9)"), 2);
    EXPECT_EQ(eval("max(4, 2, 9)"), 9);
    EXPECT_EQ(eval("abs(-3)"), 3);
    EXPECT_EQ(eval("if(0, 10, 20)"), 20);
    EXPECT_EQ(eval("if(2 > 1, 10, 20)"), 10);
    EXPECT_EQ(eval("clamp(150, 0, 100)"), 100);
    EXPECT_EQ(eval("noise(3)"), 6);          // sd * normal()
    EXPECT_EQ(eval("uniform(10, 20)"), 15);  // lo + (hi - lo) * uniform()
    EXPECT_EQ(eval("t + dt * 10"), 8);
    EXPECT_NEAR(eval("sin(pi / 2)"), 1, 1e-12);
    EXPECT_EQ(eval("round(2.5) + floor(1.9) + ceil(0.1)"), 5);
}

TEST(ScenarioExpression, AddressesBecomeReferencesReadAtEvaluation) {
    ExpressionError e;
    auto x = Expression::parse("2 * D100 + CIO0.01 + d100", resolve, e);
    ASSERT_TRUE(x);
    EXPECT_EQ(x->references(), (std::vector<std::uint32_t>{100, 10001}));
    Context c;
    c.values[100] = 5;
    c.values[10001] = 1;
    EXPECT_EQ(x->evaluate(c), 16);
    c.values[100] = 6;
    EXPECT_EQ(x->evaluate(c), 19);
}

TEST(ScenarioExpression, ErrorsCarryLineAndColumn) {
    auto e = fails("1 + FOO");
    EXPECT_EQ(e.column, 5u);
    EXPECT_NE(e.message.find("FOO"), std::string::npos);
    e = fails("D100 +\n  * 2");
    EXPECT_EQ(e.line, 2u);
    EXPECT_EQ(e.column, 3u);
    e = fails("E9_0 + 1");
    EXPECT_EQ(e.column, 1u);
    EXPECT_NE(e.message.find("no such bank"), std::string::npos);
    e = fails("min()");
    EXPECT_NE(e.message.find("at least 1"), std::string::npos);
    e = fails("abs(1, 2)");
    EXPECT_NE(e.message.find("takes 1 argument"), std::string::npos);
    e = fails("(1 + 2");
    EXPECT_NE(e.message.find("')' expected"), std::string::npos);
    e = fails("10.13.2 + 1");
    EXPECT_NE(e.message.find("CIO10.13"), std::string::npos);
    fails("12abc");
    e = fails("frobnicate(1)");
    EXPECT_NE(e.message.find("unknown function"), std::string::npos);
    fails("");
    fails("1 +");
    fails("1 2");
    fails("1 | 2");
}

TEST(ScenarioExpression, DepthAndLengthAreBounded) {
    fails(std::string(100, '(') + "1" + std::string(100, ')'));
    fails(std::string(max_expression_length + 1, '1'));
    std::string many = "1";
    for (int i = 0; i < 300; ++i)
        many = "1 + (" + many + ")";
    fails(many);
    EXPECT_EQ(eval(std::string(60, '(') + "1" + std::string(60, ')')), 1);
}

TEST(ScenarioExpression, NonFiniteResultsAreNotHidden) {
    EXPECT_TRUE(std::isinf(eval("1 / 0")));
    EXPECT_TRUE(std::isnan(eval("ln(-1)")));
}

}  // namespace
}  // namespace fins::scenario
