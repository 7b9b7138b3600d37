// plc::FileMemory: the Memory Cassette of a CP1H (disk 8003, W342 5-3-43). Items are
// host files in <root>/cassette, reached like the file devices: one directory fd opened
// without following a link, names that are single components chosen by finsd (never by
// a request). Shared by Linux and Windows: the host calls are file_memory_os.hpp's.
#include "plc/file_memory/file_memory.hpp"
#include "plc/file_memory/file_memory_device.hpp"
#include "plc/file_memory/file_memory_host.hpp"

namespace fins::plc {

using host::Kind;

Result<int> FileMemory::cassette_directory() {
    if (!cassette_mounted_) return fail(EndCode::file_device_missing);
    if (!ensure_root()) return fail(EndCode::memory_error);
    if (cassette_fd_ < 0) {
        if (host::make_directory(root_fd_, "cassette") == host::Status::failed)
            return fail(EndCode::memory_error);
        cassette_fd_ = host::open_directory(root_fd_, "cassette");
        if (cassette_fd_ < 0) return fail(EndCode::memory_error);
    }
    return cassette_fd_;
}

Result<std::optional<std::vector<std::uint8_t>>> FileMemory::cassette_item(
    const std::string& name) {
    const auto dir = cassette_directory();
    if (!dir) return Unexpected(dir.error());
    switch (host::kind_of(*dir, name)) {
        case Kind::missing:
            return std::optional<std::vector<std::uint8_t>>{};
        case Kind::file:
            if (auto content = host::read_all(*dir, name)) return content;
            return fail(EndCode::memory_error);
        default:  // something finsd did not put there: the cassette's data is broken
            return fail(EndCode::memory_error);
    }
}

EndCode FileMemory::store_cassette_item(const std::string& name, Bytes content, CivilSeconds now) {
    const auto dir = cassette_directory();
    if (!dir) return EndCode{static_cast<std::uint16_t>(dir.error().value())};
    const auto kind = host::kind_of(*dir, name);
    if (kind != Kind::missing && kind != Kind::file) return EndCode::memory_error;
    return host::replace(*dir, name, content, now, temp_counter_) ? EndCode::normal_completion
                                                                  : EndCode::memory_error;
}

EndCode FileMemory::initialize_cassette() {
    const auto dir = cassette_directory();
    if (!dir) return EndCode{static_cast<std::uint16_t>(dir.error().value())};
    if (!host::clear(*dir, false)) return EndCode::memory_error;
    host::sync(*dir);
    return EndCode::normal_completion;
}

}  // namespace fins::plc
