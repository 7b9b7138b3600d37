// The scenario expression parser and evaluator (contract in expression.hpp).
#include "scenario/expression.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>

#include "fins/error.hpp"
#include "scenario/definition.hpp"
#include "scenario/expression_eval.hpp"

namespace fins::scenario {

namespace {

// min()/max() take at most max_arguments.
constexpr std::size_t max_arguments = 32;

struct Function {
    std::string_view name;
    Expression::Op op;
    std::size_t min_arguments;
    std::size_t max_arguments;
};

constexpr std::array functions{
    Function{"min", Expression::Op::min, 1, max_arguments},
    Function{"max", Expression::Op::max, 1, max_arguments},
    Function{"abs", Expression::Op::abs, 1, 1},
    Function{"if", Expression::Op::if_else, 3, 3},
    Function{"clamp", Expression::Op::clamp, 3, 3},
    Function{"noise", Expression::Op::noise, 1, 1},
    Function{"uniform", Expression::Op::uniform, 2, 2},
    Function{"sqrt", Expression::Op::sqrt, 1, 1},
    Function{"exp", Expression::Op::exp, 1, 1},
    Function{"ln", Expression::Op::ln, 1, 1},
    Function{"sin", Expression::Op::sin, 1, 1},
    Function{"cos", Expression::Op::cos, 1, 1},
    Function{"floor", Expression::Op::floor, 1, 1},
    Function{"ceil", Expression::Op::ceil, 1, 1},
    Function{"round", Expression::Op::round, 1, 1},
};

bool is_name_start(char c) {
    return std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_';
}
bool is_name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '.';
}

}  // namespace

class ExpressionParser {
  public:
    ExpressionParser(std::string_view text, const Expression::Resolver& resolve,
                     ExpressionError& error_out)
        : text_(text), resolve_(resolve), error_(error_out) {}

    std::optional<Expression> run() {
        if (text_.size() > max_expression_length)
            return fail(0, "expression longer than " + std::to_string(max_expression_length) +
                               " characters");
        skip_space();
        if (at_end()) return fail(pos_, "empty expression");
        if (!parse_or()) return std::nullopt;
        skip_space();
        if (!at_end()) return fail(pos_, unexpected(pos_));
        return std::move(out_);
    }

  private:
    using Op = Expression::Op;

    std::nullopt_t fail(std::size_t at, std::string message) {
        if (failed_) return std::nullopt;
        failed_ = true;
        std::uint32_t line = 1, column = 1;
        for (std::size_t i = 0; i < at && i < text_.size(); ++i) {
            if (text_[i] == '\n') {
                ++line;
                column = 1;
            } else if ((static_cast<unsigned char>(text_[i]) & 0xC0) != 0x80) {
                ++column;  // characters, not bytes: a UTF-8 continuation byte is not one
            }
        }
        error_ = {line, column, std::move(message)};
        return std::nullopt;
    }
    [[nodiscard]] bool at_end() const { return pos_ >= text_.size(); }
    // "unexpected character 'é'": the whole UTF-8 character at `at`, not its first byte.
    [[nodiscard]] std::string unexpected(std::size_t at) const {
        std::size_t end = at + 1;
        if (static_cast<unsigned char>(text_[at]) >= 0xC0)
            while (end < text_.size() && end < at + 4 &&
                   (static_cast<unsigned char>(text_[end]) & 0xC0) == 0x80)
                ++end;
        return "unexpected character '" + std::string(text_.substr(at, end - at)) + "'";
    }
    void skip_space() {
        while (!at_end() && std::isspace(static_cast<unsigned char>(text_[pos_])) != 0)
            ++pos_;
    }
    bool accept(std::string_view token) {
        skip_space();
        if (text_.substr(pos_, token.size()) != token) return false;
        pos_ += token.size();
        return true;
    }
    // Tracks the evaluation stack: each instruction pushes one value after popping `pops`.
    bool emit(Op op, std::size_t pops, std::uint32_t argument = 0, double number = 0.0) {
        depth_ = depth_ + 1 - pops;
        if (depth_ > max_expression_stack) return error(pos_, "expression too complex");
        out_.stack_size_ = std::max(out_.stack_size_, depth_);
        auto& program = out_.program_;
        // A number right before + - * / is their right operand, and before noise its sd:
        // one instruction instead of two (the same arithmetic and draws, in the same
        // order; constants are in most expressions: "2 * D100", "D100 / 20", noise(2)).
        if (!program.empty() && program.back().op == Op::number) {
            const Op fused = fuse_number(op);
            if (fused != op) {
                program.back().op = fused;
                return true;
            }
        }
        program.push_back({op, argument, number});
        return true;
    }
    static Op fuse_number(Op op) {
        switch (op) {
            case Op::add:
                return Op::add_number;
            case Op::subtract:
                return Op::subtract_number;
            case Op::multiply:
                return Op::multiply_number;
            case Op::divide:
                return Op::divide_number;
            case Op::noise:
                return Op::noise_number;
            default:
                return op;
        }
    }
    bool error(std::size_t at, std::string message) {
        fail(at, std::move(message));
        return false;
    }
    bool enter() {
        if (++nesting_ > max_expression_depth)
            return error(pos_,
                         "expression nested deeper than " + std::to_string(max_expression_depth));
        return true;
    }

    bool parse_or() {
        if (!parse_and()) return false;
        while (accept("||"))
            if (!parse_and() || !emit(Op::logical_or, 2)) return false;
        return true;
    }
    bool parse_and() {
        if (!parse_comparison()) return false;
        while (accept("&&"))
            if (!parse_comparison() || !emit(Op::logical_and, 2)) return false;
        return true;
    }
    bool parse_comparison() {
        if (!parse_sum()) return false;
        for (;;) {
            Op op;
            if (accept("<="))
                op = Op::less_equal;
            else if (accept(">="))
                op = Op::greater_equal;
            else if (accept("=="))
                op = Op::equal;
            else if (accept("!="))
                op = Op::not_equal;
            else if (accept("<"))
                op = Op::less;
            else if (accept(">"))
                op = Op::greater;
            else
                return true;
            if (!parse_sum() || !emit(op, 2)) return false;
        }
    }
    bool parse_sum() {
        if (!parse_product()) return false;
        for (;;) {
            Op op;
            if (accept("+"))
                op = Op::add;
            else if (accept("-"))
                op = Op::subtract;
            else
                return true;
            if (!parse_product() || !emit(op, 2)) return false;
        }
    }
    bool parse_product() {
        if (!parse_unary()) return false;
        for (;;) {
            Op op;
            if (accept("*"))
                op = Op::multiply;
            else if (accept("/"))
                op = Op::divide;
            else if (accept("%"))
                op = Op::modulo;
            else
                return true;
            if (!parse_unary() || !emit(op, 2)) return false;
        }
    }
    bool parse_unary() {
        if (!enter()) return false;
        bool ok;
        skip_space();
        // "!=" never starts an operand, so a leading '!' is always "not".
        if (accept("-"))
            ok = parse_unary() && emit(Op::negate, 1);
        else if (accept("!"))
            ok = parse_unary() && emit(Op::logical_not, 1);
        else if (accept("+"))
            ok = parse_unary();
        else
            ok = parse_power();
        --nesting_;
        return ok;
    }
    bool parse_power() {
        if (!parse_primary()) return false;
        if (accept("^")) return parse_unary() && emit(Op::power, 2);
        return true;
    }
    bool parse_primary() {
        skip_space();
        if (at_end()) return error(pos_, "expression ends where a value is expected");
        const std::size_t start = pos_;
        const char c = text_[pos_];
        if (c == '(') {
            ++pos_;
            if (!parse_or()) return false;
            if (!accept(")")) return error(pos_, "')' expected");
            return true;
        }
        if (std::isdigit(static_cast<unsigned char>(c)) != 0 || c == '.') return parse_number();
        if (!is_name_start(c)) return error(start, unexpected(start));
        while (!at_end() && is_name_char(text_[pos_]))
            ++pos_;
        // A name does not go on with a non-ASCII character (D1é): that character is wrong.
        if (!at_end() && static_cast<unsigned char>(text_[pos_]) >= 0x80)
            return error(pos_, unexpected(pos_));
        const std::string_view name = text_.substr(start, pos_ - start);
        skip_space();
        if (!at_end() && text_[pos_] == '(') return parse_call(name, start);
        if (name == "t") return emit(Op::time, 0);
        if (name == "dt") return emit(Op::tick, 0);
        if (name == "pi") return emit(Op::number, 0, 0, std::numbers::pi);
        if (name == "true") return emit(Op::number, 0, 0, 1.0);
        if (name == "false") return emit(Op::number, 0, 0, 0.0);
        auto address = parse_address(name);
        if (!address) {
            const auto e = address.error();
            if (e == AddressError::word_out_of_range || e == AddressError::bit_out_of_range)
                return error(start, address_error(name, e));
            return error(start, "'" + std::string(name) + "' is neither an address nor a name");
        }
        std::string message;
        auto reference = resolve_(*address, message);
        if (!reference) return error(start, std::string(name) + ": " + message);
        if (std::find(out_.references_.begin(), out_.references_.end(), *reference) ==
            out_.references_.end())
            out_.references_.push_back(*reference);
        return emit(Op::load, 0, *reference);
    }
    bool parse_call(std::string_view name, std::size_t start) {
        const auto* function = std::find_if(functions.begin(), functions.end(),
                                            [&](const Function& f) { return f.name == name; });
        if (function == functions.end())
            return error(start, "unknown function '" + std::string(name) + "'");
        ++pos_;  // '('
        std::size_t count = 0;
        if (!accept(")")) {
            for (;;) {
                if (count == function->max_arguments) return error(start, arity(*function));
                if (!parse_or()) return false;
                ++count;
                if (accept(")")) break;
                if (!accept(",")) return error(pos_, "',' or ')' expected");
            }
        }
        if (count < function->min_arguments) return error(start, arity(*function));
        if (function->op == Op::noise || function->op == Op::uniform) out_.uses_random_ = true;
        return emit(function->op, count, static_cast<std::uint32_t>(count));
    }
    static std::string arity(const Function& f) {
        const std::string name(f.name);
        if (f.min_arguments == f.max_arguments)
            return name + "() takes " + std::to_string(f.min_arguments) + " argument" +
                   (f.min_arguments == 1 ? "" : "s");
        return name + "() takes at least " + std::to_string(f.min_arguments) + " and at most " +
               std::to_string(f.max_arguments) + " arguments";
    }
    bool parse_number() {
        const std::size_t start = pos_;
        double value = 0.0;
        if (text_.substr(pos_, 2) == "0x" || text_.substr(pos_, 2) == "0X") {
            pos_ += 2;
            std::uint64_t v = 0;
            const auto* first = text_.data() + pos_;
            auto [end, ec] = std::from_chars(first, text_.data() + text_.size(), v, 16);
            if (ec != std::errc{} || end == first) return error(start, "bad hexadecimal number");
            pos_ += static_cast<std::size_t>(end - first);
            value = static_cast<double>(v);
        } else {
            const auto* first = text_.data() + pos_;
            auto [end, ec] = std::from_chars(first, text_.data() + text_.size(), value);
            if (ec != std::errc{} || end == first) return error(start, "bad number");
            pos_ += static_cast<std::size_t>(end - first);
        }
        if (!at_end() && is_name_char(text_[pos_]))
            return error(start, "bad number (a CIO address is written CIO10.13, not 10.13)");
        return emit(Op::number, 0, 0, value);
    }

    std::string_view text_;
    const Expression::Resolver& resolve_;
    ExpressionError& error_;
    Expression out_;
    std::size_t pos_ = 0;
    std::size_t depth_ = 0;
    std::size_t nesting_ = 0;
    bool failed_ = false;
};

std::optional<Expression> Expression::parse(std::string_view text, const Resolver& resolve,
                                            ExpressionError& error) {
    return ExpressionParser(text, resolve, error).run();
}

double Expression::evaluate(ExpressionContext& context) const noexcept {
    return run(context);
}

}  // namespace fins::scenario
