// Fuzzes the 22 xx request decoders (W342 5-3-32 .. 5-3-43): the first byte picks the
// command, the rest are its parameters. A decoder either refuses with the end code the
// server answers (1001/1002) or yields a command that encodes back to exactly the
// input: names and paths are framed, never interpreted, here.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/commands/file_memory.hpp"
#include "fins/commands/memory_cassette.hpp"
#include "fins/frame.hpp"

namespace {

void check(bool ok) {
    if (!ok) __builtin_trap();
}

template <class C>
void round_trip(fins::Bytes parameters) {
    const auto command = C::decode(parameters);
    if (!command) {
        const auto e = command.error();
        check(e == fins::EndCode::command_too_short || e == fins::EndCode::command_too_long);
        return;
    }
    std::vector<std::uint8_t> out(parameters.size() + 16);
    fins::ByteWriter w(out);
    command->encode(w);
    check(!w.overflowed() && w.size() == parameters.size());
    for (std::size_t i = 0; i < parameters.size(); ++i)
        check(out[i] == parameters[i]);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace fins;
    if (size == 0 || size > max_parameter_size + 1) return 0;
    const Bytes parameters(data + 1, size - 1);
    switch (data[0] % 12) {
        case 0:
            round_trip<FileNameRead>(parameters);
            break;
        case 1:
            round_trip<SingleFileRead>(parameters);
            break;
        case 2:
            round_trip<SingleFileWrite>(parameters);
            break;
        case 3:
            round_trip<FileMemoryFormat>(parameters);
            break;
        case 4:
            round_trip<FileDelete>(parameters);
            break;
        case 5:
            round_trip<FileCopy>(parameters);
            break;
        case 6:
            round_trip<FileNameChange>(parameters);
            break;
        case 7:
            round_trip<MemoryAreaFileTransfer>(parameters);
            break;
        case 8:
            round_trip<ParameterAreaFileTransfer>(parameters);
            break;
        case 9:
            round_trip<ProgramAreaFileTransfer>(parameters);
            break;
        case 10:
            round_trip<MemoryCassetteTransfer>(parameters);
            break;
        default:
            round_trip<DirectoryCreateDelete>(parameters);
            break;
    }
    return 0;
}
