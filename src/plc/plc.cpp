#include "plc/plc.hpp"

#include <utility>

namespace fins::plc {

Plc::Plc(Profile profile, std::unique_ptr<Storage> storage)
    : storage_(storage ? std::move(storage) : std::make_unique<Storage>()),
      memory_(std::move(profile), *storage_),
      parameters_(memory_.profile(), *storage_),
      program_(memory_.profile(), *storage_),
      loop_control_(memory_.profile(), *storage_),
      clock_(memory_.profile(), *storage_),
      scan_cycle_(memory_.profile(), *storage_),
      errors_(memory_.profile(), *storage_),
      messages_(memory_.profile(), *storage_),
      write_access_log_(memory_.profile(), *storage_),
      files_(memory_.profile()) {
    // Log records carry the PLC's own clock (as 07 02 set it), like a real CPU Unit.
    errors_.use_clock(&clock_);
    write_access_log_.use_clock(&clock_);
}

void Plc::set_network_write_protection_setting(NetworkWriteProtectionSetting setting) {
    if (setting.nodes.size() > max_protection_nodes) setting.nodes.resize(max_protection_nodes);
    network_write_protection_ = std::move(setting);
}

bool Plc::network_write_protected_from(const NodeAddress& source) const noexcept {
    bool listed = false;
    for (const auto& n : network_write_protection_.nodes)
        if (n.network == source.network && (n.node == any_node || n.node == source.node))
            listed = true;
    switch (network_write_protection_.mode) {
        case NetworkWriteProtection::off:
            return false;
        case NetworkWriteProtection::all:
            return true;
        case NetworkWriteProtection::listed:
            return listed;
        case NetworkWriteProtection::all_except_listed:
            return !listed;
    }
    return true;
}

void Plc::power_on(std::chrono::system_clock::time_point now) noexcept {
    if (scan_cycle_.powered()) return;
    if (mode_ == OperatingMode::program)
        scan_cycle_.stop(now);
    else
        scan_cycle_.start(now);
}

void Plc::change_mode(OperatingMode mode, std::chrono::system_clock::time_point now) noexcept {
    if (mode == OperatingMode::program) {
        scan_cycle_.stop(now);
    } else if (mode_ == OperatingMode::program) {
        scan_cycle_.stop(now);  // a mode set without change_mode may have left it running
        scan_cycle_.start(now);
    } else {
        scan_cycle_.start(now);  // RUN <-> MONITOR: no-op unless it was stopped
    }
    mode_ = mode;
}

tl::expected<OpenedPlc, PlcOpenError> open_plc(const Profile& profile,
                                               const std::optional<std::filesystem::path>& data_dir,
                                               StorageOptions options, bool reset_state) {
    OpenedPlc opened;
    for (;;) {
        std::error_code error;
        std::unique_ptr<Storage> storage;
        if (data_dir) {
            auto file = Storage::open(*data_dir, profile.name, options);
            if (file) storage = std::move(*file);
            if (!file) error = file.error();
        }
        if (!error) {
            opened.plc = std::make_unique<Plc>(profile, std::move(storage));
            const auto sealed = opened.plc->storage().seal();
            if (sealed) return opened;
            error = sealed.error();
            opened.plc.reset();  // unmaps and unlocks the refused file
        }
        if (!Storage::is_refusal(error) || !reset_state || opened.moved_aside)
            return tl::unexpected(PlcOpenError{error});
        auto aside = Storage::set_aside(*data_dir);
        if (!aside) return tl::unexpected(PlcOpenError{aside.error(), true});
        opened.moved_aside = std::move(*aside);
        opened.refusal = error;
    }
}

}  // namespace fins::plc
