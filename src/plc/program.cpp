#include "plc/program.hpp"

#include <algorithm>

namespace fins::plc {

namespace {

// 5-3-15: program area size in K words; a word is 2 bytes.
constexpr std::size_t bytes_per_kword = 1024 * 2;

Unexpected fail(EndCode e) {
    return Unexpected(make_error_code(e));
}

bool aligned(std::uint32_t v) noexcept {
    return v % program_alignment == 0;
}

ProgramRange make_range(std::uint32_t address, std::uint32_t count, std::uint32_t size) noexcept {
    return ProgramRange{address, static_cast<std::uint16_t>(count),
                        count != 0 && address + count == size};
}

}  // namespace

UserProgram::UserProgram(const Profile& profile, Storage& storage)
    : bytes_(storage.array<std::uint8_t>(
          "program", std::size_t{profile.program_kwords} * bytes_per_kword, Retention::retained)),
      state_(storage.object<State>("program_state", Retention::retained)) {}

// W342 5-3-10.
Result<ProgramReadPlan> UserProgram::plan_read(const ProgramAreaRead& command) const {
    if (prohibit_transfer()) return fail(EndCode::read_protected);
    if (command.program_number != program_number_all) return fail(EndCode::program_missing);
    // "Bit 15 must be OFF (0) in the command format."
    if (command.last) return fail(EndCode::parameter_error);
    if (!aligned(command.address) || !aligned(command.count))
        return fail(EndCode::access_size_error);
    if (command.count > max_program_read_bytes) return fail(EndCode::response_too_long);
    if (command.address >= size()) return fail(EndCode::address_range_error);
    ProgramReadPlan plan;
    std::uint32_t count = command.count;
    if (count > size() - command.address) {
        count = size() - command.address;
        plan.code = EndCode::address_range_exceeded;
    }
    plan.range = make_range(command.address, count, size());
    return plan;
}

// W342 5-3-11.
Result<ProgramRange> UserProgram::plan_write(const ProgramAreaWrite& command) const {
    if (prohibit_overwrite()) return fail(EndCode::write_protected);
    if (command.program_number != program_number_all) return fail(EndCode::program_missing);
    if (command.count > max_program_write_bytes) return fail(EndCode::command_too_long);
    if (!aligned(command.address) || !aligned(command.count))
        return fail(EndCode::access_size_error);
    if (command.address >= size()) return fail(EndCode::address_range_error);
    if (command.count > size() - command.address) return fail(EndCode::address_range_exceeded);
    if (command.data.size() != command.count) return fail(EndCode::elements_data_mismatch);
    return make_range(command.address, command.count, size());
}

// W342 5-3-12.
EndCode UserProgram::check_clear(const ProgramAreaClear& command) const noexcept {
    if (prohibit_overwrite()) return EndCode::write_protected;
    if (command.program_number != program_number_all) return EndCode::program_missing;
    if (command.clear_code != clear_without_interrupt_tasks &&
        command.clear_code != clear_with_interrupt_tasks)
        return EndCode::parameter_error;
    return EndCode::normal_completion;
}

void UserProgram::read(const ProgramRange& range, ByteWriter& out) const noexcept {
    if (range.address > size() || range.count > size() - range.address) return;
    out.bytes(bytes_.subspan(range.address, range.count));
}

void UserProgram::write(const ProgramRange& range, Bytes data, bool last) noexcept {
    if (range.address > size() || range.count > size() - range.address) return;
    const auto n = std::min<std::size_t>(range.count, data.size());
    std::copy_n(data.begin(), n, bytes_.begin() + range.address);
    state_.download_in_progress = last ? 0 : 1;
}

void UserProgram::clear(std::uint8_t clear_code) noexcept {
    std::fill(bytes_.begin(), bytes_.end(), std::uint8_t{0});
    state_ = State{};
    state_.interrupt_tasks = clear_code == clear_with_interrupt_tasks ? 1 : 0;
}

}  // namespace fins::plc
