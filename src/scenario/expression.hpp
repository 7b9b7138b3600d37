// The scenario expression language: parsed once at start into a flat program for a stack
// machine, then evaluated every tick with no allocation.
//
//   numbers      12  0.5  1e3  0x1F
//   constants    t (scenario seconds)  dt (tick seconds)  pi  true (1)  false (0)
//   tags         D100  CIO0.00  W3.15  H10  E3_100  T5  ... any address of fins/address.hpp;
//                the Resolver turns each into a reference number
//   operators    ( )  unary - + !  ^ (power, right-associative)  * / %  + -
//                < <= > >= == !=  &&  ||     (precedence low to high: || && comparisons + * ^)
//   functions    min(a, b, ...) max(a, b, ...) abs(x) if(c, a, b) clamp(x, lo, hi)
//                noise(sd) (normal, mean 0) uniform(lo, hi) sqrt(x) exp(x) ln(x) sin(x)
//                cos(x) floor(x) ceil(x) round(x)
// Every value is a double; a condition is true when it is not 0; comparisons and ! give 1
// or 0. if(), && and || evaluate all their operands (random draws stay in step whatever
// the condition).
//
// Why not libmuparser (Debian libmuparser-dev): its identifiers cannot hold the '.' of
// CIO0.00 (it is the decimal point), it reports a character offset only, its callbacks
// have no context for the scenario's seeded random numbers, and binding one double per
// variable name would need a copy of every tag's value before each evaluation. The
// language here is ~300 lines, bounded (length, depth), and fuzzed (fuzz_scenario_expr).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fins/address.hpp"

namespace fins::scenario {

inline constexpr std::size_t max_expression_length = 4096;
inline constexpr std::size_t max_expression_depth = 64;  // nested parentheses and calls
// Deepest evaluation stack a program may need.
inline constexpr std::size_t max_expression_stack = 256;

// A position inside the expression text, 1-based.
struct ExpressionError {
    std::uint32_t line = 1;
    std::uint32_t column = 1;
    std::string message;
};

// What evaluation reads: reference values, random draws and the time.
class ExpressionContext {
  public:
    virtual ~ExpressionContext() = default;
    virtual double load(std::uint32_t reference) noexcept = 0;
    virtual double normal() noexcept = 0;   // mean 0, sd 1
    virtual double uniform() noexcept = 0;  // [0, 1)
    virtual double time() const noexcept = 0;
    virtual double tick() const noexcept = 0;
};

class Expression {
  public:
    // Turns an address into a reference number, or an error message (e.g. "the CJ2H
    // has no E25_0"). Called once per address occurrence, at parse time.
    using Resolver =
        std::function<std::optional<std::uint32_t>(const Address&, std::string& error)>;

    static std::optional<Expression> parse(std::string_view text, const Resolver& resolve,
                                           ExpressionError& error);

    // NaN or infinity when the arithmetic gives one (1/0, ln(-1), ...).
    double evaluate(ExpressionContext& context) const noexcept;
    // The same for any context with ExpressionContext's members (expression_eval.hpp).
    template <class Context>
    double run(Context& context) const noexcept;

    // The reference numbers the expression reads, each once.
    [[nodiscard]] const std::vector<std::uint32_t>& references() const noexcept {
        return references_;
    }
    [[nodiscard]] bool uses_random() const noexcept { return uses_random_; }

    enum class Op : std::uint8_t {
        number,
        load,
        time,
        tick,
        negate,
        logical_not,
        add,
        subtract,
        multiply,
        divide,
        modulo,
        power,
        less,
        less_equal,
        greater,
        greater_equal,
        equal,
        not_equal,
        logical_and,
        logical_or,
        min,
        max,
        abs,
        if_else,
        clamp,
        noise,
        uniform,
        sqrt,
        exp,
        ln,
        sin,
        cos,
        floor,
        ceil,
        round,
        // A number followed by + - * / or noise, as one instruction with the number in
        // `number` (made by parse()).
        add_number,
        subtract_number,
        multiply_number,
        divide_number,
        noise_number,
        // Never made by parse(): a context that keeps its references' words in one array
        // (the scenario's image) rewrites a `load` of a one-word integer into these, with
        // `argument` the word's index in that array, read by the context's word(index).
        load_int16,
        load_uint16,
    };
    struct Instruction {
        Op op = Op::number;
        std::uint32_t argument = 0;  // load: reference; load_int16/uint16: word; min/max: count
        double number = 0.0;
    };
    // The compiled program (a scenario copies its tags' programs into one array).
    [[nodiscard]] const std::vector<Instruction>& program() const noexcept { return program_; }
    // Runs `size` instructions of a program at `program` (expression_eval.hpp).
    template <class Context>
    static double run(const Instruction* program, std::size_t size, Context& context) noexcept;

  private:
    std::vector<Instruction> program_;
    std::vector<std::uint32_t> references_;
    std::size_t stack_size_ = 0;
    bool uses_random_ = false;
    friend class ExpressionParser;
};

}  // namespace fins::scenario
