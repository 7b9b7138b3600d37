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
// so it survives SIGKILL of the process. A damaged or foreign state file is reported by
// seal() with a clear error; it is never silently replaced by zeroes.
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

class Storage {
  public:
    // All sections on the heap, zeroed.
    Storage();
    ~Storage();
    Storage(const Storage&) = delete;
    Storage& operator=(const Storage&) = delete;

    // Opens (or creates) `<dir>/finsd.state` for the model `profile_id` (the profile's
    // model string plus anything that changes section sizes). Fails when the directory
    // cannot be created or the file cannot be opened/locked, or when it exists but is not
    // a finskit state file of this format version and profile.
    static Result<std::unique_ptr<Storage>> open(const std::filesystem::path& dir,
                                                 std::string_view profile_id);

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
    // existing state file (a section missing, extra, or of another size).
    [[nodiscard]] Result<void> seal();
    // True when retained sections were restored from an existing state file.
    [[nodiscard]] bool restored() const noexcept;
    // The state file, empty without a data directory.
    [[nodiscard]] std::filesystem::path path() const;
    // Asks the kernel to write retained sections to disk now (msync); a clean shutdown
    // calls it. Not needed for SIGKILL safety.
    void flush() noexcept;

    struct Impl;

  private:
    explicit Storage(std::unique_ptr<Impl> impl);
    std::span<std::byte> section(std::string_view name, std::size_t bytes, std::size_t align,
                                 Retention retention);
    std::unique_ptr<Impl> impl_;
};

}  // namespace fins::plc
