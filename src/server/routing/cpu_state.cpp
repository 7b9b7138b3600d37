// open_cpu_state: a CPU Unit's PLC on its state file, with the same words for a single
// node and each CPU Unit of a plant (see plant.hpp).
#include <cstdio>
#include <fstream>

#include <fmt/format.h>

#include "plc/storage/storage_format.hpp"
#include "server/routing/plant.hpp"

namespace fins::server {

// The header holds the profile name NUL-terminated (plc/storage/storage.cpp): look for
// each known name there rather than depend on the header's offsets.
std::string state_file_profile(const std::filesystem::path& file) {
    std::ifstream f(file, std::ios::binary);
    std::string head(4096, '\0');
    f.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(f.gcount()));
    for (const auto& p : plc::profiles())
        if (head.find(std::string(1, '\0') + p.name + std::string(1, '\0')) != std::string::npos)
            return p.name;
    return "unknown";
}

tl::expected<std::unique_ptr<plc::Plc>, CpuStateRefusal> open_cpu_state(
    const plc::Profile& profile, const std::optional<std::filesystem::path>& data_dir,
    plc::StorageOptions options, bool reset_state, std::string_view who) {
    using plc::Storage;
    auto opened = plc::open_plc(profile, data_dir, options, reset_state);
    const std::string file = data_dir ? (*data_dir / "finsd.state").string() : "(heap)";
    if (!opened) {
        const std::error_code error = opened.error().error;
        if (opened.error().setting_aside)
            return tl::make_unexpected(CpuStateRefusal{
                error, fmt::format("{}{}: cannot move it aside: {}", who, file, error.message())});
        std::string why = error.message();
        if (data_dir && error == plc::state_file::make_error(plc::state_file::Error::other_profile))
            why += fmt::format(": the file is for profile '{}', this {} runs '{}'",
                               state_file_profile(*data_dir / "finsd.state"),
                               who.empty() ? "finsd" : "CPU Unit", profile.name);
        return tl::make_unexpected(CpuStateRefusal{
            error, fmt::format("{}{}: {}{}", who, file, why,
                               Storage::is_refusal(error)
                                   ? "; finsd never replaces it by itself: start with "
                                     "--reset-state to move it aside and begin with empty "
                                     "retained memory"
                                   : "")});
    }
    if (opened->moved_aside)
        std::fprintf(stderr,
                     "finsd: warning: %.*s%s: %s; --reset-state moved it to %s: retained memory "
                     "starts empty\n",
                     static_cast<int>(who.size()), who.data(), file.c_str(),
                     opened->refusal.message().c_str(), opened->moved_aside->string().c_str());
    auto& storage = opened->plc->storage();
    if (data_dir && storage.restored() && !storage.checksums_verified())
        std::fprintf(stderr,
                     "finsd: warning: %.*s%s was not stopped cleanly (SIGKILL, crash or power "
                     "loss; or it was just converted from an earlier format): its header and "
                     "section table are intact; its data has no valid checksums to check\n",
                     static_cast<int>(who.size()), who.data(), storage.path().string().c_str());
    return std::move(opened->plc);
}

}  // namespace fins::server
