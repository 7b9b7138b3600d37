// The file memory of a CS/CJ CPU Unit (W342 5-3-32 .. 5-3-42, frames-serial-files 4):
// the memory card (disk 8000) and EM file memory (disk 8001), each a directory under
// one root on the host (finsd: the data directory, else a private temporary directory
// removed at exit): <root>/card and <root>/em. A CP1H's Memory Cassette (disk 8003,
// 22 20, W342 5-3-43) is <root>/cassette (file_memory_cassette.cpp).
//
// Safety: every name and path is checked against the CPU Unit's rules (8.3 names of
// letters, digits and ! & $ # ' { } - ^ ( ) _ ~; no "~~" start, no 00/E5 first byte, no
// DOS device names; paths "\A\B" of at most 65 characters and 4 directories below the
// root) before any host call, and the host is then walked one component at a time with
// openat(O_NOFOLLOW) (Windows: checked CreateFileW opens, file_memory_os.hpp): a symlink
// (or junction) planted in a device directory is never followed. Names are
// case-insensitive and stored upper case (FAT convention; the seed does not say); host
// entries that are not valid upper-case 8.3 names (".volume", temp files, "foo.txt")
// are invisible to FINS.
//
// Durability: a write that creates or replaces bytes of a file goes to a temp file in
// the same directory, is fsync'ed and renamed over the old one (directory fsync'ed): old
// or new content, never a mix. A write that only extends a file (append, or 0003 at the
// file's end) is one pwrite into the page cache, so an acknowledged write survives
// SIGKILL of finsd. Extending writes of one transfer reuse an open descriptor (see
// OpenFile below): a chunk costs fstatat + pwrite + futimens. Capacity is the device's size (card:
// kilobytes from the profile or config; EM: 64 KiB per file bank); the file bytes in use are
// counted, and a write that would exceed it answers 1104 and changes nothing.
//
// End codes (choices where the seed only names the code, pinned by tests/plc and
// tests/server file_memory tests): 110C bad name, path, disk number, mode or count;
// 2301 device missing (card not inserted, EM not configured as file memory); 2006 file
// or directory missing on a read, 2106 on a write; 2107 name exists; 2108 directory not
// empty; 2103 directory depth limit; 1103 position past the file's end; 1104 capacity
// or 32-bit size exceeded; 250F a host I/O error
// (a full host disk too), after which the file is exactly as the last acknowledged write
// left it: an extending write the host refuses part way is cut back (ftruncate).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "fins/commands/file_memory.hpp"
#include "fins/error.hpp"
#include "plc/clock.hpp"
#include "plc/profile.hpp"

namespace fins::plc {

// EM file memory: one bank of 32,768 words = 64 KiB of file space.
inline constexpr std::uint32_t em_bank_bytes = 32768 * 2;
// The data files' header (fins/commands/file_memory.hpp).
using fins::data_file_header_size;
// Directories below the root: 5 levels counting the root (CJ2SW p.271).
inline constexpr std::size_t max_file_directories = 4;

class FileMemory {
  public:
    explicit FileMemory(const Profile& profile);
    ~FileMemory();
    FileMemory(const FileMemory&) = delete;
    FileMemory& operator=(const FileMemory&) = delete;

    // Keeps the devices under `root` (created if missing) and removes temp files a
    // killed finsd left behind. Without attach(), the first file access creates a
    // private temporary root that the destructor removes.
    // A device directory (<root>/card, em, cassette) that is a symlink was put there by
    // whoever owns the data directory (no FINS command creates one), e.g. to keep the card
    // on another disk: it is followed here, once, and the directory it names is that
    // device until the next attach(); below it nothing is followed. One that does not name
    // a directory fails attach() (ENOTDIR, or the error opening it).
    Result<void> attach(const std::filesystem::path& root);
    struct DeviceLink {
        std::string device;            // "card", "em", "cassette"
        std::filesystem::path target;  // what the symlink says
        std::error_code error;         // why it was refused, if it was
    };
    // The device symlinks the last attach() found (for finsd's log).
    [[nodiscard]] const std::vector<DeviceLink>& device_links() const noexcept {
        return device_links_;
    }
    [[nodiscard]] std::filesystem::path root() const { return root_; }

    // The memory card: inserted with a capacity, or not (2301).
    [[nodiscard]] bool card_inserted() const noexcept { return card_kbytes_ != 0; }
    [[nodiscard]] std::uint32_t card_kbytes() const noexcept { return card_kbytes_; }
    void insert_card(std::uint32_t kbytes) noexcept { card_kbytes_ = kbytes; }
    void remove_card() noexcept {
        card_kbytes_ = 0;
        forget_open_files(0);
    }
    // The first EM bank that is file memory; nullopt (or >= the profile's banks): none.
    [[nodiscard]] std::optional<std::uint8_t> em_file_bank() const noexcept { return em_bank_; }
    void set_em_file_bank(std::optional<std::uint8_t> bank) noexcept;
    // 05 01 "EM non-file memory size": banks before the file banks.
    [[nodiscard]] std::uint8_t em_non_file_banks() const noexcept;

    // The Memory Cassette of a CP1H (disk 8003, 22 20 only; W342 5-3-43): mounted when
    // the profile has one, else 2301. It holds named items, one host file each in
    // <root>/cassette, each replaced whole (temp file, fsync, rename): the 22 20 handler
    // (server/handlers/memory_cassette.cpp) decides what they contain.
    [[nodiscard]] bool cassette_mounted() const noexcept { return cassette_mounted_; }
    void mount_cassette(bool mounted) noexcept { cassette_mounted_ = mounted; }
    // The item's bytes, or nullopt when the cassette does not hold it.
    Result<std::optional<std::vector<std::uint8_t>>> cassette_item(const std::string& name);
    EndCode store_cassette_item(const std::string& name, Bytes content, CivilSeconds now);
    EndCode initialize_cassette();

    // The commands (validated in full before anything changes). `now` is the CPU Unit's
    // clock, recorded as the date of what they create (5-3-34, 5-3-39 .. 5-3-42).
    Result<FileNameReadResponse> list(const FileNameRead& command);
    Result<SingleFileReadResponse> read(const SingleFileRead& command);
    EndCode write(const SingleFileWrite& command, CivilSeconds now);
    // 22 04. `current_em_bank`: 1101 when EM is formatted while the current bank is a
    // file bank other than EM0 (5-3-35 note).
    EndCode format(std::uint16_t disk, std::uint8_t current_em_bank, CivilSeconds now);
    Result<std::uint16_t> remove(const FileDelete& command);
    EndCode copy(const FileCopy& command);
    EndCode rename(const FileNameChange& command);
    EndCode directory(const DirectoryCreateDelete& command, CivilSeconds now);

    // Whole files for 22 0A .. 22 0C: load (2006 missing) and create (2107 exists, 1104 full).
    Result<std::vector<std::uint8_t>> load(std::uint16_t disk, const FileName& file,
                                           const std::string& directory);
    EndCode create(std::uint16_t disk, const FileName& file, const std::string& directory,
                   Bytes content, CivilSeconds now);

    // Name rules on text ("NAME.EXT"): the canonical upper-case host name, or nullopt.
    static std::optional<std::string> canonical_name(std::string_view text);
    // Name rules on the 12 wire bytes (padding included).
    static std::optional<std::string> canonical_name(const FileName& name);
    // Path rules: "\A\B" gives {"A", "B"} (canonical), "" and "\" the root; nullopt
    // when the path breaks them. visible(): a host entry FINS may see (canonical as is).
    static std::optional<std::vector<std::string>> parse_directory(std::string_view path);
    static bool visible(std::string_view name);

    struct Device;

    // Descriptors kept open between the chunks of a transfer (for tests and docs/file-memory.md).
    static constexpr std::size_t max_open_files = 4;
    // An open file unused for longer (CPU clock seconds, either way) is closed at the
    // next 22 03.
    static constexpr CivilSeconds open_file_idle_seconds = 2;
    [[nodiscard]] std::size_t open_files() const noexcept { return open_files_.size(); }

  private:
    // A file that 22 02 read or 22 03 extended, kept open (read-write) with its
    // directory so that the next chunk
    // skips the path walk and the open: found by device and "\DIR\NAME" key, used only
    // while statx(dir, name, AT_SYMLINK_NOFOLLOW) still names the same regular file
    // (a host-side rename, delete or symlink swap falls back to the checked walk). Its
    // chunks are written undated; the file gets its CPU clock date when it is closed
    // or before 22 01 / 22 07 / a load reads dates (date_open_files()).
    // Dropped by every 22 xx change other than 22 03 on that device, card removal, EM
    // reconfiguration, attach(); the least recently used goes first past
    // max_open_files; closed at destruction.
    struct OpenFile {
        std::size_t device = 0;
        std::string key;
        int directory = -1;
        int fd = -1;
        std::uint64_t host_device = 0;
        std::uint64_t inode = 0;
        CivilSeconds last_write = 0;
        std::uint64_t last_use = 0;  // LRU order
        bool undated = false;        // written since last dated: date it last_write
    };
    // "\DIR\SUB\NAME": what find_open_file() looks for.
    static std::string open_file_key(const std::vector<std::string>& path, const std::string& name);
    OpenFile* find_open_file(std::size_t device, const std::string& key) noexcept;
    // Takes ownership of `directory` on success; nullptr when `name` cannot be opened.
    OpenFile* keep_open(std::size_t device, std::string key, int directory,
                        const std::string& name);
    void close_open_file(OpenFile* file) noexcept;
    // Closes the cached descriptors of `device` (all when nullopt).
    void forget_open_files(std::optional<std::size_t> device = std::nullopt) noexcept;
    // Gives the open files written since they were last dated their CPU clock date
    // (futimens once, not once per chunk): before anything reads file dates.
    void date_open_files() noexcept;
    void close_idle_files(CivilSeconds now) noexcept;

    Result<Device> open_device(std::uint16_t disk);
    Result<void> ensure_root();
    // The cassette's host directory (created and kept open), or an end code.
    Result<int> cassette_directory();
    void close_devices() noexcept;
    // File bytes on the device: counted at first use, then tracked by every change made
    // here (recounted after 22 04 / 22 05); temp files of a replace in progress excluded.
    std::uint64_t bytes_in_use(const Device& d);

    const Profile& profile_;
    std::filesystem::path root_;
    int root_fd_ = -1;
    bool own_root_ = false;
    std::uint32_t card_kbytes_ = 0;
    std::optional<std::uint8_t> em_bank_;
    unsigned temp_counter_ = 0;
    int device_fds_[2] = {-1, -1};  // card, em
    std::optional<std::uint64_t> used_[2];
    bool cassette_mounted_ = false;
    int cassette_fd_ = -1;
    std::vector<OpenFile> open_files_;
    std::vector<DeviceLink> device_links_;
    std::uint64_t use_counter_ = 0;
};

}  // namespace fins::plc
