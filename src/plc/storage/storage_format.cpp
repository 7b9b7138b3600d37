// Storage's error category (storage_format.hpp): one line each, what is wrong with the
// state file. finsd adds what the operator can do (--reset-state) to the refusals. And the
// check of a cleanly stopped file's section checksums.
#include "plc/storage/storage_format.hpp"

#include <cerrno>
#include <string>

namespace fins::plc::state_file {

namespace {

class Category final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.storage"; }
    std::string message(int c) const override {
        switch (static_cast<Error>(c)) {
            case Error::not_a_state_file:
                return "not a finsd state file";
            case Error::unsupported_version:
                return "state file written by an unsupported finsd format version";
            case Error::other_profile:
                return "state file belongs to another PLC profile (use another --data-dir)";
            case Error::damaged:
                return "state file is damaged (size or section table)";
            case Error::layout_mismatch:
                return "state file sections do not match this profile's memory layout";
            case Error::in_use:
                return "state file is in use by another finsd";
            case Error::too_many_sections:
                return "too many retained sections";
            case Error::duplicate_section:
                return "two retained sections of the same name";
            case Error::profile_id_too_long:
                return "profile id too long for a state file";
            case Error::empty:
                return "state file is empty (0 bytes): its retained memory is gone";
            case Error::incomplete:
                return "state file is damaged: its \"complete\" flag is cleared, which finsd "
                       "never writes";
            case Error::header_checksum:
                return "state file is damaged: its header fails its checksum";
            case Error::section_checksum:
                return "state file is damaged: retained data changed after finsd stopped "
                       "cleanly (a section fails its checksum)";
            case Error::no_space:
                return "cannot reserve the state file's space on disk (file system full, "
                       "quota or file size limit): free space or use another --data-dir";
        }
        return "storage error";
    }
};

const Category category;

}  // namespace

std::error_code make_error(Error e) noexcept {
    return {static_cast<int>(e), category};
}

bool is_refusal(const std::error_code& e) noexcept {
    if (e.category() != category) return false;
    switch (static_cast<Error>(e.value())) {
        case Error::not_a_state_file:
        case Error::unsupported_version:
        case Error::other_profile:
        case Error::damaged:
        case Error::layout_mismatch:
        case Error::empty:
        case Error::incomplete:
        case Error::header_checksum:
        case Error::section_checksum:
            return true;
        default:
            return false;
    }
}

Result<void> verify_section_checksums(os::Handle fd, std::uint64_t size, const Header& header) {
    auto view = os::map(fd, 0, static_cast<std::size_t>(size), false);
    if (!view) return Unexpected(view.error());
    const std::byte* file = view->data;
    const Descriptor& d = header.descriptor;
    bool intact = true;
    for (std::uint32_t i = 0; i < d.count && intact; ++i) {
        const auto& e = d.entries[i];
        intact = crc32c({file + e.offset, e.size}) == header.seal.section_crc[i];
    }
    os::unmap(view->base, view->span);
    if (!intact) return Unexpected(make_error(Error::section_checksum));
    return {};
}

}  // namespace fins::plc::state_file
