// Expression::run, the evaluator, as a template over the context: the scenario's own
// context (a final class) gets its loads and random draws inlined, with no virtual call
// per reference. Included by expression.cpp (for ExpressionContext) and the tick.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "scenario/expression.hpp"

namespace fins::scenario {

template <class Context>
double Expression::run(Context& context) const noexcept {
    return run(program_.data(), program_.size(), context);
}

template <class Context>
double Expression::run(const Instruction* program, std::size_t size, Context& context) noexcept {
    std::array<double, max_expression_stack> stack;
    std::size_t top = 0;  // number of values on the stack
    auto truth = [](double v) { return v != 0.0 && !std::isnan(v) ? 1.0 : 0.0; };
    for (const Instruction* end = program + size; program != end; ++program) {
        const Instruction& in = *program;
        switch (in.op) {
            case Op::number:
                stack[top++] = in.number;
                break;
            case Op::load:
                stack[top++] = context.load(in.argument);
                break;
            case Op::load_int16:
            case Op::load_uint16:
                // Only a context with word() has programs rewritten so (Scenario::Impl).
                if constexpr (requires { context.word(std::uint32_t{}); }) {
                    const std::uint16_t w = context.word(in.argument);
                    stack[top++] = in.op == Op::load_int16
                                       ? static_cast<double>(static_cast<std::int16_t>(w))
                                       : static_cast<double>(w);
                } else {
                    stack[top++] = std::nan("");
                }
                break;
            case Op::add_number:
                stack[top - 1] = stack[top - 1] + in.number;
                break;
            case Op::subtract_number:
                stack[top - 1] = stack[top - 1] - in.number;
                break;
            case Op::multiply_number:
                stack[top - 1] = stack[top - 1] * in.number;
                break;
            case Op::divide_number:
                stack[top - 1] = stack[top - 1] / in.number;
                break;
            case Op::noise_number:
                stack[top++] = in.number * context.normal();
                break;
            case Op::time:
                stack[top++] = context.time();
                break;
            case Op::tick:
                stack[top++] = context.tick();
                break;
            case Op::negate:
                stack[top - 1] = -stack[top - 1];
                break;
            case Op::logical_not:
                stack[top - 1] = 1.0 - truth(stack[top - 1]);
                break;
            case Op::abs:
                stack[top - 1] = std::fabs(stack[top - 1]);
                break;
            case Op::sqrt:
                stack[top - 1] = std::sqrt(stack[top - 1]);
                break;
            case Op::exp:
                stack[top - 1] = std::exp(stack[top - 1]);
                break;
            case Op::ln:
                stack[top - 1] = std::log(stack[top - 1]);
                break;
            case Op::sin:
                stack[top - 1] = std::sin(stack[top - 1]);
                break;
            case Op::cos:
                stack[top - 1] = std::cos(stack[top - 1]);
                break;
            case Op::floor:
                stack[top - 1] = std::floor(stack[top - 1]);
                break;
            case Op::ceil:
                stack[top - 1] = std::ceil(stack[top - 1]);
                break;
            case Op::round:
                stack[top - 1] = std::round(stack[top - 1]);
                break;
            case Op::noise:
                stack[top - 1] = stack[top - 1] * context.normal();
                break;
            case Op::min:
            case Op::max: {
                const std::size_t first = top - in.argument;
                double v = stack[first];
                for (std::size_t i = first + 1; i < top; ++i)
                    v = in.op == Op::min ? std::fmin(v, stack[i]) : std::fmax(v, stack[i]);
                top = first;
                stack[top++] = v;
                break;
            }
            case Op::if_else: {
                top -= 2;
                stack[top - 1] = truth(stack[top - 1]) != 0.0 ? stack[top] : stack[top + 1];
                break;
            }
            case Op::clamp: {
                top -= 2;
                const double lo = stack[top], hi = stack[top + 1];
                stack[top - 1] = std::fmin(std::fmax(stack[top - 1], lo), hi);
                break;
            }
            default: {
                const double b = stack[--top];
                double& a = stack[top - 1];
                switch (in.op) {
                    case Op::add:
                        a = a + b;
                        break;
                    case Op::subtract:
                        a = a - b;
                        break;
                    case Op::multiply:
                        a = a * b;
                        break;
                    case Op::divide:
                        a = a / b;
                        break;
                    case Op::modulo:
                        a = std::fmod(a, b);
                        break;
                    case Op::power:
                        a = std::pow(a, b);
                        break;
                    case Op::less:
                        a = a < b ? 1.0 : 0.0;
                        break;
                    case Op::less_equal:
                        a = a <= b ? 1.0 : 0.0;
                        break;
                    case Op::greater:
                        a = a > b ? 1.0 : 0.0;
                        break;
                    case Op::greater_equal:
                        a = a >= b ? 1.0 : 0.0;
                        break;
                    case Op::equal:
                        a = a == b ? 1.0 : 0.0;
                        break;
                    case Op::not_equal:
                        a = a != b ? 1.0 : 0.0;
                        break;
                    case Op::logical_and:
                        a = truth(a) * truth(b);
                        break;
                    case Op::logical_or:
                        a = std::fmax(truth(a), truth(b));
                        break;
                    case Op::uniform:
                        a = a + (b - a) * context.uniform();
                        break;
                    default:
                        break;
                }
                break;
            }
        }
    }
    return top == 1 ? stack[0] : std::nan("");
}

}  // namespace fins::scenario
