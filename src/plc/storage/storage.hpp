// Backing memory for the virtual PLC's state, like a CPU Unit's RAM: some sections are
// battery-backed (retained across power cycles), the rest is cleared at power-on.
//
// Every model (I/O memory, parameter areas, program, clock, logs ...) takes its state
// from here at construction, by name: array<T>() for runs of words or records,
// object<T>() for a small trivially-copyable struct. Names and sizes must be the same
// on every start for a given profile; Storage checks that a reopened state file holds
// exactly the sections asked for.
//
// Without a data directory everything lives on the heap (a PLC whose battery is gone).
// With one, retained sections are mapped from `<dir>/finsd.state` with MAP_SHARED: a
// write the PLC acknowledged is in the kernel's page cache before the response leaves,
// so it survives SIGKILL of the process; with Durability::power, commit() also puts it
// on disk before the answer (power loss).
//
// The state file (storage.cpp has the layout):
// - is created atomically: built as `finsd.state.new` with every byte reserved
//   (posix_fallocate, so a full disk is an error at start, never a SIGBUS later),
//   synced, renamed to `finsd.state`, directory synced. A crash at any step leaves no
//   state file or a complete one.
// - carries CRC-32C checksums of its header and, after a clean stop, of every retained
//   section; a cleanly stopped file whose bytes changed is refused at start.
// - is never replaced or emptied here: a refused file stays as it is until the operator
//   moves it aside (set_aside(), finsd --reset-state).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

#include "fins/error.hpp"

namespace fins::plc {

enum class Retention : std::uint8_t {
    cleared,   // zero at every start (CIO, W, timers ...)
    retained,  // kept across restarts when a data directory is set (H, D, EM, counters ...)
};

// What an acknowledged write survives.
enum class Durability : std::uint8_t {
    process,  // SIGKILL or a crash of finsd (the kernel writes the pages back later)
    power,    // power loss too: commit() fdatasyncs the file before each write's answer
};

struct StorageOptions {
    Durability durability = Durability::process;
};

class Storage {
  public:
    // All sections on the heap, zeroed.
    Storage();
    ~Storage();
    Storage(const Storage&) = delete;
    Storage& operator=(const Storage&) = delete;

    // Opens `<dir>/finsd.state` for the model `profile_id` (the profile's model string
    // plus anything that changes section sizes), or starts creating it when there is
    // none. Fails when the directory cannot be created or locked (another finsd: "in
    // use"), when the file cannot be fully reserved on disk, or when it exists but is
    // refused (is_refusal(): empty, not a state file, another version or profile,
    // incomplete, damaged, or a checksum that no longer matches). Never writes to a file
    // it refuses.
    static Result<std::unique_ptr<Storage>> open(const std::filesystem::path& dir,
                                                 std::string_view profile_id,
                                                 StorageOptions options = {});
    // True for errors that are about an existing state file's content, i.e. the ones an
    // operator resolves by moving the file aside (set_aside).
    [[nodiscard]] static bool is_refusal(const std::error_code& error) noexcept;
    // Renames `<dir>/finsd.state` to `<dir>/finsd.state.replaced-YYYYMMDDTHHMMSSZ` (a
    // free name; never deletes anything) and syncs the directory. Returns the new path.
    // Fails "in use" while another Storage holds the directory.
    static Result<std::filesystem::path> set_aside(const std::filesystem::path& dir);

    // `count` zero-initialised (new) or restored (retained, existing file) elements.
    template <class T>
    std::span<T> array(std::string_view name, std::size_t count, Retention retention) {
        static_assert(std::is_trivially_copyable_v<T>, "stored state must be plain data");
        auto raw = section(name, count * sizeof(T), alignof(T), retention);
        return {reinterpret_cast<T*>(raw.data()), raw.empty() ? 0 : count};
    }
    template <class T>
    T& object(std::string_view name, Retention retention) {
        return array<T>(name, 1, retention)[0];
    }

    // Call once every model has taken its sections: reports a layout mismatch with an
    // existing state file (a section missing, extra, or of another size), or a section
    // that could not be reserved. A new file appears under its name here (atomically);
    // an existing one is marked "running" (its section checksums no longer hold).
    [[nodiscard]] Result<void> seal();
    // True when retained sections were restored from an existing state file.
    [[nodiscard]] bool restored() const noexcept;
    // True when the restored file had been stopped cleanly and every section matched
    // its checksum; false after a SIGKILL or power loss (only the header and section
    // table were checked) and for a new file.
    [[nodiscard]] bool checksums_verified() const noexcept;
    // False when the sealed state file is now shorter than it was (truncated from
    // outside, storage_guard.hpp): close() then leaves it alone. True without a file.
    [[nodiscard]] bool intact() const noexcept;
    // The state file, empty without a data directory.
    [[nodiscard]] std::filesystem::path path() const;
    // Asks the kernel to write retained sections to disk now (msync). Not needed for
    // SIGKILL safety.
    void flush() noexcept;
    // Clean stop: writes every section to disk, then their checksums and the "stopped
    // cleanly" flag. The destructor does it for a sealed file; no retained write may
    // follow. Idempotent.
    void close() noexcept;

    // Called after each command that may change retained state, before its answer.
    // Durability::process: nothing (one branch). Durability::power: fdatasync of the
    // state file; false when it failed (the change is in memory, not on disk).
    [[nodiscard]] bool commit() noexcept { return !sync_on_commit_ || sync(); }
    // How many times commit() synced the file (tests).
    [[nodiscard]] std::uint64_t syncs() const noexcept { return syncs_; }

    // Tests only: called with the name of each step of creating a new state file
    // ("locked", "temporary file created", "header written", "section reserved",
    // "synced", "renamed", "directory synced"), so that a test can end the process
    // there. nullptr (the default) for none.
    static void set_creation_probe(void (*probe)(const char* step)) noexcept;

    struct Impl;

  private:
    explicit Storage(std::unique_ptr<Impl> impl);
    std::span<std::byte> section(std::string_view name, std::size_t bytes, std::size_t align,
                                 Retention retention);
    bool sync() noexcept;
    std::unique_ptr<Impl> impl_;
    bool sync_on_commit_ = false;
    std::uint64_t syncs_ = 0;
};

}  // namespace fins::plc
