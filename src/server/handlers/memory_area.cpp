// 01 xx I/O memory area access: MEMORY AREA READ/WRITE/FILL, MULTIPLE MEMORY AREA
// READ, MEMORY AREA TRANSFER (W342 5-3-2 .. 5-3-6). Address validation and element
// encodings live in plc::IoMemory; these functions only apply each command's rules.
#include <array>

#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

using plc::ElementRange;
using plc::Intent;

namespace {

// A handler's end code from a failed locate().
template <class T>
EndCode failure(const Result<T>& r) noexcept {
    return to_end_code(r.error());
}

}  // namespace

// W342 5-3-2. count 0: the start address is still validated, then a normal response
// with no data. A response longer than 1,998 data bytes (999 words) answers 110B.
// No allocation on this path: elements are encoded straight into `out`.
EndCode execute(HandlerContext& context, const MemoryAreaRead& command, ByteWriter& out) noexcept {
    const auto& memory = context.plc.memory();
    const auto range = memory.locate(command.start, command.count, use_read, Intent::read);
    if (!range) return failure(range);
    if (range->byte_size() > max_response_data_size || range->byte_size() > out.remaining())
        return EndCode::response_too_long;
    memory.read(*range, out, context.request.now);
    return EndCode::normal_completion;
}

// W342 5-3-3. Address checks (1101/1103/1104/2101) come before the data length check
// (1003). count 0 with no data: normal completion, nothing written.
EndCode execute(HandlerContext& context, const MemoryAreaWrite& command, ByteWriter&) noexcept {
    auto& memory = context.plc.memory();
    const auto range = memory.locate(command.start, command.count, use_write, Intent::write);
    if (!range) return failure(range);
    return memory.write(*range, command.data);
}

// W342 5-3-4. Word codes only (the area table's use_word_ops).
EndCode execute(HandlerContext& context, const MemoryAreaFill& command, ByteWriter&) noexcept {
    auto& memory = context.plc.memory();
    const auto range = memory.locate(command.start, command.count, use_word_ops, Intent::write);
    if (!range) return failure(range);
    return memory.fill(*range, command.value);
}

// W342 5-3-5. Every element is validated before anything is written: an error in any
// element answers that element's end code with no data.
EndCode execute(HandlerContext& context, const MultipleMemoryAreaRead& command,
                ByteWriter& out) noexcept {
    if (command.items.size() > max_multiple_read_elements) return EndCode::command_too_long;
    const auto& memory = context.plc.memory();
    std::array<ElementRange, max_multiple_read_elements> ranges{};
    std::size_t bytes = 0;
    for (std::size_t i = 0; i < command.items.size(); ++i) {
        const auto range = memory.locate(command.items[i], 1, use_multi_read, Intent::read);
        if (!range) return failure(range);
        ranges[i] = *range;
        bytes += 1 + range->byte_size();
    }
    if (bytes > max_response_data_size || bytes > out.remaining())
        return EndCode::response_too_long;
    for (std::size_t i = 0; i < command.items.size(); ++i) {
        out.u8(command.items[i].area_code);  // each element echoes its area code
        memory.read(ranges[i], out, context.request.now);
    }
    return EndCode::normal_completion;
}

// W342 5-3-6. Source checked before destination; word codes only on both sides.
EndCode execute(HandlerContext& context, const MemoryAreaTransfer& command, ByteWriter&) {
    auto& memory = context.plc.memory();
    const auto source = memory.locate(command.source, command.count, use_word_ops, Intent::read);
    if (!source) return failure(source);
    const auto destination =
        memory.locate(command.destination, command.count, use_word_ops, Intent::write);
    if (!destination) return failure(destination);
    return memory.transfer(*source, *destination);
}

namespace {

constexpr HandlerEntry memory_area_table[] = {
    entry<MemoryAreaRead>(),         entry<MemoryAreaWrite>(),    entry<MemoryAreaFill>(),
    entry<MultipleMemoryAreaRead>(), entry<MemoryAreaTransfer>(),
};

}  // namespace

std::span<const HandlerEntry> memory_area_handlers() noexcept {
    return memory_area_table;
}

}  // namespace fins::server::handlers
