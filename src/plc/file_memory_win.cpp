// plc::FileMemory on Windows: not ported yet (docs/windows.md, "finsd.exe"). The Linux
// implementation (file_memory*.cpp) keeps its root safe by walking it with openat and
// O_NOFOLLOW one component at a time; a Windows one must do the same with handles
// (FILE_FLAG_OPEN_REPARSE_POINT, a check of each opened directory's final path against
// the root), which is not written. Until then every file device answers as a CPU Unit
// without one: 2301 (file device missing), and the PLC reports no memory card, no EM file
// memory and no Memory Cassette. Nothing on the host is created or read.
#ifdef _WIN32
#include "plc/file_memory.hpp"
#include "plc/file_memory_device.hpp"

namespace fins::plc {

FileMemory::FileMemory(const Profile& profile) : profile_(profile) {}

FileMemory::~FileMemory() = default;

void FileMemory::set_em_file_bank(std::optional<std::uint8_t>) noexcept {}

std::uint8_t FileMemory::em_non_file_banks() const noexcept {
    return profile_.em_banks;
}

Result<void> FileMemory::attach(const std::filesystem::path& root) {
    root_ = root;
    return {};
}

void FileMemory::forget_open_files(std::optional<std::size_t>) noexcept {}

Result<std::optional<std::vector<std::uint8_t>>> FileMemory::cassette_item(const std::string&) {
    return fail(EndCode::file_device_missing);
}

EndCode FileMemory::store_cassette_item(const std::string&, Bytes, CivilSeconds) {
    return EndCode::file_device_missing;
}

EndCode FileMemory::initialize_cassette() {
    return EndCode::file_device_missing;
}

Result<FileNameReadResponse> FileMemory::list(const FileNameRead&) {
    return fail(EndCode::file_device_missing);
}

Result<SingleFileReadResponse> FileMemory::read(const SingleFileRead&) {
    return fail(EndCode::file_device_missing);
}

EndCode FileMemory::write(const SingleFileWrite&, CivilSeconds) {
    return EndCode::file_device_missing;
}

EndCode FileMemory::format(std::uint16_t, std::uint8_t, CivilSeconds) {
    return EndCode::file_device_missing;
}

Result<std::uint16_t> FileMemory::remove(const FileDelete&) {
    return fail(EndCode::file_device_missing);
}

EndCode FileMemory::copy(const FileCopy&) {
    return EndCode::file_device_missing;
}

EndCode FileMemory::rename(const FileNameChange&) {
    return EndCode::file_device_missing;
}

EndCode FileMemory::directory(const DirectoryCreateDelete&, CivilSeconds) {
    return EndCode::file_device_missing;
}

Result<std::vector<std::uint8_t>> FileMemory::load(std::uint16_t, const FileName&,
                                                   const std::string&) {
    return fail(EndCode::file_device_missing);
}

EndCode FileMemory::create(std::uint16_t, const FileName&, const std::string&, Bytes,
                           CivilSeconds) {
    return EndCode::file_device_missing;
}

}  // namespace fins::plc
#endif
