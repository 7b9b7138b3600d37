#include "plc/loop_control.hpp"

#include "fins/commands/loop_control.hpp"

namespace fins::plc {

namespace {

// The ITEM lists of loop_control.hpp.
constexpr FunctionBlockItemSpec system_common_items[] = {
    {0, 2, 0, 0},
    {4, 2, 100, 0},
    {5, 1, 1, 0},
    {10, 4, 86400, 0},
};

constexpr FunctionBlockItemSpec basic_pid_items[] = {
    {0, 2, 11, 0},    {4, 2, 50, 0},  {6, 2, 4000, 500}, {7, 2, 5000, 100}, {8, 2, 2000, 1000},
    {10, 2, 1000, 0}, {11, 2, 0, 20}, {12, 2, 0, 0},     {20, 1, 0, 0},     {30, 4, 0, 3600},
};

constexpr FunctionBlockItemSpec step_ladder_items[] = {
    {0, 2, 301, 0}, {4, 2, 100, 0}, {8, 2, 1, 0},  {11, 2, 0, 0}, {12, 2, 0, 0},
    {13, 2, 0, 0},  {14, 2, 0, 0},  {15, 2, 0, 0}, {16, 2, 0, 0}, {17, 2, 0, 0},
    {18, 2, 0, 0},  {19, 2, 0, 0},  {20, 2, 0, 0},
};

constexpr std::uint16_t step_ladder_first_command_item = 11;

constexpr FunctionBlock registered[] = {
    {0, 0, "System Common", system_common_items},
    {1, 11, "Basic PID", basic_pid_items},
    {2, 11, "Basic PID", basic_pid_items},
    {3, 11, "Basic PID", basic_pid_items},
    {100, 301, "Step Ladder Program", step_ladder_items, step_ladder_first_command_item},
};

}  // namespace

LoopControl::LoopControl(const Profile& profile, Storage&) : present_(profile.loop_control) {}

std::span<const FunctionBlock> LoopControl::blocks() noexcept {
    return registered;
}

const FunctionBlock* LoopControl::find_block(std::uint16_t address) noexcept {
    if (address > max_function_block) return nullptr;
    for (const auto& block : registered)
        if (block.address == address) return &block;
    return nullptr;
}

std::optional<FunctionBlockItemValue> LoopControl::read(const FunctionBlock& block,
                                                        std::uint16_t item) noexcept {
    if (item > max_item_number || item >= block.first_unreadable_item) return std::nullopt;
    for (const auto& spec : block.items) {
        if (spec.item != item) continue;
        const std::uint32_t value = spec.base + spec.per_block * block.address;
        FunctionBlockItemValue out;
        out.length = spec.length;
        for (std::uint8_t i = 0; i < spec.length && i < out.bytes.size(); ++i)
            out.bytes[i] = static_cast<std::uint8_t>(value >> (8 * (spec.length - 1 - i)));
        return out;
    }
    return std::nullopt;
}

void LoopControl::set_sources(const void* owner, std::vector<ItemSource> sources) {
    sources_owner_ = owner;
    sources_ = std::move(sources);
}

void LoopControl::clear_sources(const void* owner) noexcept {
    if (owner != sources_owner_) return;
    sources_owner_ = nullptr;
    sources_.clear();
}

std::optional<FunctionBlockItemValue> LoopControl::read_item(const FunctionBlock& block,
                                                             std::uint16_t item) const noexcept {
    auto value = read(block, item);
    if (!value) return value;
    for (const auto& source : sources_) {
        if (source.block != block.address || source.item != item) continue;
        const std::uint16_t w0 = source.words[0];
        switch (value->length) {
            case 1:
                value->bytes[0] = static_cast<std::uint8_t>(w0);
                break;
            case 2:
                value->bytes[0] = static_cast<std::uint8_t>(w0 >> 8);
                value->bytes[1] = static_cast<std::uint8_t>(w0);
                break;
            default: {
                // CS/CJ 32-bit values: the low word first (fins/values.hpp).
                const std::uint32_t v = (std::uint32_t{source.words[1]} << 16) | w0;
                for (std::uint8_t i = 0; i < 4; ++i)
                    value->bytes[i] = static_cast<std::uint8_t>(v >> (8 * (3 - i)));
                break;
            }
        }
        break;
    }
    return value;
}

}  // namespace fins::plc
