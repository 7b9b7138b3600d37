// The virtual CPU Unit: a Profile, its I/O memory, the operating mode and the state
// the execution conditions of W342 5-1-2 look at. No sockets, no frames, no clock.
//
// Power-on mode is RUN: a CS/CJ CPU Unit whose PLC Setup keeps the default startup
// mode and has no Programming Console attached starts in RUN mode (CJ2: "RUN mode"
// is the default startup mode). With no user program that changes nothing but the
// execution conditions (e.g. 03 07 PROGRAM AREA WRITE answers 2206 until STOP).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <tl/expected.hpp>

#include "fins/frame.hpp"
#include "plc/clock.hpp"
#include "plc/errors.hpp"
#include "plc/file_memory/file_memory.hpp"
#include "plc/io_memory.hpp"
#include "plc/loop_control.hpp"
#include "plc/messages.hpp"
#include "plc/parameter_areas.hpp"
#include "plc/profile.hpp"
#include "plc/program.hpp"
#include "plc/scan_cycle.hpp"
#include "plc/storage/storage.hpp"
#include "plc/write_access_log.hpp"

namespace fins::plc {

enum class OperatingMode : std::uint8_t { program, monitor, run };

// PLC Setup "Write Protection from FINS Commands Sent to CPU Units via Networks"
// (W342 5-1-2 note 5, W596 2-5). Which network nodes' FINS write commands answer 2102:
enum class NetworkWriteProtection : std::uint8_t {
    off,                // none
    all,                // every network node
    listed,             // only the listed nodes (note 5: "from specified network nodes")
    all_except_listed,  // every node but the listed ones (the CS/CJ PLC Setup's "nodes
                        // excluded from write protection")
};

// At most 32 listed nodes, as the CS/CJ PLC Setup's excluded-nodes table holds.
inline constexpr std::size_t max_protection_nodes = 32;
// A listed entry with this node number matches every node of its network.
inline constexpr std::uint8_t any_node = 0xFF;

struct NetworkWriteProtectionSetting {
    NetworkWriteProtection mode = NetworkWriteProtection::off;
    // Network + node of the requests' source address (SNA, SA1; the unit is ignored).
    // Compared exactly as the request header carries them; node FF = any node.
    std::vector<NodeAddress> nodes;
};

class Plc {
  public:
    // `storage` holds the state (nullptr: all on the heap, nothing retained). Every
    // model takes its sections from it here; call storage().seal() afterwards.
    explicit Plc(Profile profile = cj2h(), std::unique_ptr<Storage> storage = nullptr);

    [[nodiscard]] const Profile& profile() const noexcept { return memory_.profile(); }
    IoMemory& memory() noexcept { return memory_; }
    [[nodiscard]] const IoMemory& memory() const noexcept { return memory_; }

    Storage& storage() noexcept { return *storage_; }
    ParameterAreas& parameters() noexcept { return parameters_; }
    UserProgram& program() noexcept { return program_; }
    LoopControl& loop_control() noexcept { return loop_control_; }
    Clock& clock() noexcept { return clock_; }
    ScanCycle& scan_cycle() noexcept { return scan_cycle_; }
    ErrorState& errors() noexcept { return errors_; }
    [[nodiscard]] const ErrorState& errors() const noexcept { return errors_; }
    Messages& messages() noexcept { return messages_; }
    WriteAccessLog& write_access_log() noexcept { return write_access_log_; }
    FileMemory& files() noexcept { return files_; }
    [[nodiscard]] const FileMemory& files() const noexcept { return files_; }

    // Power-on at `now` in the current mode (RUN unless set_mode() said otherwise): the
    // scan cycle runs from here whether anyone asks or not (scan_cycle.hpp). The server
    // calls it when it starts serving; the dispatcher before every request, for a Plc no
    // server started (tests). Nothing once powered.
    void power_on(std::chrono::system_clock::time_point now) noexcept;

    [[nodiscard]] OperatingMode mode() const noexcept { return mode_; }
    // Sets the mode without touching the scan cycle (tests and power-on only).
    void set_mode(OperatingMode mode) noexcept { mode_ = mode; }
    // Changes the operating mode as 04 01/04 02 do: leaving PROGRAM starts the program
    // (the scan cycle restarts its statistics), entering PROGRAM stops it.
    void change_mode(OperatingMode mode, std::chrono::system_clock::time_point now) noexcept;

    // The node holding the access right (0C 01/02), if any (W342 5-3-1 "Access Right").
    [[nodiscard]] const std::optional<NodeAddress>& access_right_holder() const noexcept {
        return access_right_holder_;
    }
    void set_access_right_holder(std::optional<NodeAddress> holder) noexcept {
        access_right_holder_ = holder;
    }
    // True when a device other than `requester` holds the access right.
    [[nodiscard]] bool access_right_held_by_other(const NodeAddress& requester) const noexcept {
        return access_right_holder_.has_value() && !(*access_right_holder_ == requester);
    }

    // PLC Setup "Write Protection from FINS Commands Sent to CPU Units via Networks"
    // (W342 5-1-2 note 5). True when the protection is on in any mode.
    [[nodiscard]] bool network_write_protection() const noexcept {
        return network_write_protection_.mode != NetworkWriteProtection::off;
    }
    // On: every network node (NetworkWriteProtection::all); off: none. The node list
    // is kept for a later listed mode.
    void set_network_write_protection(bool on) noexcept {
        network_write_protection_.mode =
            on ? NetworkWriteProtection::all : NetworkWriteProtection::off;
    }
    // Takes at most max_protection_nodes entries (the rest are dropped). Allocates:
    // a configuration call, never on the request path.
    void set_network_write_protection_setting(NetworkWriteProtectionSetting setting);
    [[nodiscard]] const NetworkWriteProtectionSetting& network_write_protection_setting()
        const noexcept {
        return network_write_protection_;
    }
    // True when a FINS write command from `source` (arrived over a network) is refused
    // with 2102 under the current setting.
    [[nodiscard]] bool network_write_protected_from(const NodeAddress& source) const noexcept;

    // UM read protection set from a Peripheral Device.
    [[nodiscard]] bool um_read_protection() const noexcept { return um_read_protection_; }
    void set_um_read_protection(bool on) noexcept { um_read_protection_ = on; }
    // The password a Programming Device gives to release UM read protection (set with
    // the protection, W342 5-1-3 2602 "incorrect password"); empty = none.
    [[nodiscard]] const std::string& um_password() const noexcept { return um_password_; }
    void set_um_password(std::string password) { um_password_ = std::move(password); }

    // DIP switch pin 1 ON: UM write-protected.
    [[nodiscard]] bool dip_write_protection() const noexcept { return dip_write_protection_; }
    void set_dip_write_protection(bool on) noexcept { dip_write_protection_ = on; }

  private:
    std::unique_ptr<Storage> storage_;  // first: every model below takes sections from it
    IoMemory memory_;
    ParameterAreas parameters_;
    UserProgram program_;
    LoopControl loop_control_;
    Clock clock_;
    ScanCycle scan_cycle_;
    ErrorState errors_;
    Messages messages_;
    WriteAccessLog write_access_log_;
    FileMemory files_;
    OperatingMode mode_ = OperatingMode::run;
    std::optional<NodeAddress> access_right_holder_;
    NetworkWriteProtectionSetting network_write_protection_;
    bool um_read_protection_ = false;
    std::string um_password_;
    bool dip_write_protection_ = false;
};

// A CPU Unit on its state file in `data_dir` (on the heap without one), sealed. A file
// refused for its content (Storage::is_refusal) fails, unless `reset_state`: then it is
// moved aside once and the CPU Unit starts with empty retained memory. The finsd of one
// node and each CPU Unit of a plant open through here and only word the outcome.
struct OpenedPlc {
    std::unique_ptr<Plc> plc;
    std::optional<std::filesystem::path> moved_aside;  // where the refused file went
    std::error_code refusal;                           // why it was refused
};
struct PlcOpenError {
    std::error_code error;
    bool setting_aside = false;  // the refused file could not be moved aside
};
tl::expected<OpenedPlc, PlcOpenError> open_plc(const Profile& profile,
                                               const std::optional<std::filesystem::path>& data_dir,
                                               StorageOptions options, bool reset_state);

}  // namespace fins::plc
