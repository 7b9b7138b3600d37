// Loop Control Board function blocks read by 02 40 (seed 001).
//
// The board exists only when Profile::loop_control is set. finskit registers a small,
// fixed set of function blocks whose ITEM values are derived from the block address,
// so reads return real, predictable data (the ITEM numbers and lengths are finskit's
// model, not copied from the Function Block Reference Manual's ITEM lists):
//
//   block 000  System Common (model 000)
//              ITEM 000 block model (2) = 0   ITEM 004 operation cycle (2) = 100 (x10 ms)
//              ITEM 005 run status (1) = 1    ITEM 010 run time in s (4) = 86400
//   block 001-003  Basic PID (model 011), b = block address
//              ITEM 000 block model (2) = 11  ITEM 004 operation cycle (2) = 50
//              ITEM 006 PV (2) = 4000 + 500 b ITEM 007 SP (2) = 5000 + 100 b
//              ITEM 008 MV (2) = 2000 + 1000 b   (PV/SP/MV in 0.01 %)
//              ITEM 010 P (2) = 1000          ITEM 011 I in s (2) = 20 b
//              ITEM 012 D in s (2) = 0        ITEM 020 alarm status (1) = 0
//              ITEM 030 run time in s (4) = 3600 b
//   block 100  Step Ladder Program (model 301)
//              ITEM 000 block model (2) = 301 ITEM 004 operation cycle (2) = 100
//              ITEM 008 step number (2) = 1   ITEM 011-020 sequence commands (2) = 0,
//              registered but not readable (seed 001: "excluding the sequence commands
//              (ITEM011 onwards) in the Step Ladder Program block (Block Model 301)")
//
// Values are read-only: finsd answers only 02 40 ITEM read (02 41 ITEM write is undefined,
// 0401), so nothing is stored. A scenario may give ITEMs live values (set_sources, issue
// 19: the temperature loop's PV): such an ITEM answers the words of a memory address
// the scenario writes, its length unchanged (1 byte: the low byte of the word; 2: the
// word; 4: the two words as a CS/CJ 32-bit value, low word first).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

struct FunctionBlockItemSpec {
    std::uint16_t item = 0;
    std::uint8_t length = 0;  // 1, 2 or 4 bytes
    std::uint32_t base = 0;   // value = base + per_block x block address
    std::uint32_t per_block = 0;
};

struct FunctionBlock {
    std::uint16_t address = 0;  // 0-999
    std::uint16_t model = 0;    // block model number
    std::string_view name;
    std::span<const FunctionBlockItemSpec> items;  // ascending ITEM numbers
    std::uint16_t first_unreadable_item = 0xFFFF;  // Step Ladder: 011
};

struct FunctionBlockItemValue {
    std::uint8_t length = 0;
    std::array<std::uint8_t, 4> bytes{};  // big-endian, the first `length` bytes
};

class LoopControl {
  public:
    LoopControl(const Profile& profile, Storage& storage);

    // A Loop Control Board is mounted (else 02 40 answers 0401).
    [[nodiscard]] bool present() const noexcept { return present_; }
    // Every registered block, ascending by address.
    [[nodiscard]] static std::span<const FunctionBlock> blocks() noexcept;
    // nullptr for an address that is out of range or not registered (1101).
    [[nodiscard]] static const FunctionBlock* find_block(std::uint16_t address) noexcept;
    // The ITEM's value, or nullopt when the block has no such ITEM or it may not be read.
    [[nodiscard]] static std::optional<FunctionBlockItemValue> read(const FunctionBlock& block,
                                                                    std::uint16_t item) noexcept;

    // An ITEM whose value is memory: `words` points at the word(s) of the CPU Unit's
    // memory it reads (one word, or two for a 4-byte ITEM).
    struct ItemSource {
        std::uint16_t block = 0;
        std::uint16_t item = 0;
        const std::uint16_t* words = nullptr;
    };
    // Replaces every source with `sources`, held for `owner` (a running scenario);
    // clear_sources(owner) drops them unless another owner has set its own since.
    void set_sources(const void* owner, std::vector<ItemSource> sources);
    void clear_sources(const void* owner) noexcept;
    // What 02 40 answers: the ITEM's source when it has one, else read().
    [[nodiscard]] std::optional<FunctionBlockItemValue> read_item(
        const FunctionBlock& block, std::uint16_t item) const noexcept;

  private:
    bool present_ = false;
    const void* sources_owner_ = nullptr;
    std::vector<ItemSource> sources_;
};

}  // namespace fins::plc
