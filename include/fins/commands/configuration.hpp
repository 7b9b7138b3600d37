// Machine configuration reading: CPU UNIT DATA READ 05 01 and CONNECTION DATA READ
// 05 02 (W342 5-3-15, 5-3-16; frames 6/0501, 6/0502). Same command-type shape as
// fins/commands/memory_area.hpp.
//
// 05 01 response data (after the end code), by data selector:
//   none (all)  model 20 | version 20 | system use 40 | area data 12 |
//               CPU Bus Units 64 | remote I/O 1 | CPU information 1     = 158 bytes
//   00          model 20 | version 20 | system use 40 | area data 12     =  92 bytes
//   01          CPU Bus Units 64 | remote I/O 1 | CPU information 1      =  66 bytes
// W342 5-3-15: the number of SYSMAC BUS masters "is returned in a single byte"; real
// CS/CJ/CP CPU Units answer 158 bytes and libfins refuses any other length
// (fins-frames.md 0501, resolved discrepancy). The 2-byte remote I/O field of the
// CV-series diagram (Wireshark's dissector, 161 bytes with MRC SRC and end code) is
// still accepted by decode_response(), which reads CPU information last.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// ---- 05 01 ----

// 5-3-15 "Data (command)".
enum class CpuUnitDataSection : std::uint8_t {
    model_and_area = 0x00,  // CPU Unit model, internal system version, area data
    units_and_info = 0x01,  // CPU Bus Unit configuration, remote I/O data, CPU information
};

inline constexpr std::size_t cpu_model_size = 20;       // ASCII, space padded
inline constexpr std::size_t cpu_version_size = 20;     // ASCII, NUL padded
inline constexpr std::size_t cpu_system_use_size = 40;  // DIP switch, largest EM bank, 38 x 00
inline constexpr std::size_t cpu_area_data_size = 12;
inline constexpr std::size_t cpu_bus_unit_slots = 16;       // unit numbers 0-15
inline constexpr std::size_t cpu_bus_unit_block_size = 64;  // 16 x 2 bytes + 32 reserved
inline constexpr std::size_t cpu_remote_io_size = 1;        // W342 5-3-15 "a single byte"
inline constexpr std::size_t cpu_model_and_area_size =
    cpu_model_size + cpu_version_size + cpu_system_use_size + cpu_area_data_size;  // 92
inline constexpr std::size_t cpu_units_and_info_size =
    cpu_bus_unit_block_size + cpu_remote_io_size + 1;  // 66
// CPU Bus Unit configuration word: bit 15 = unit mounted, bits 0-14 = model ID.
inline constexpr std::uint16_t cpu_bus_unit_present = 0x8000;

// 5-3-15 "Area data" (12 bytes).
struct CpuUnitAreaData {
    std::uint16_t program_kwords = 0;       // usable program area, K words
    std::uint8_t iom_kbytes = 0;            // bit-accessible I/O memory, K bytes ("always 23")
    std::uint16_t dm_words = 0;             // "always 32,768"
    std::uint8_t timer_counter_kwords = 0;  // x 1,024 ("always 8")
    std::uint8_t em_non_file_banks = 0;     // EM banks without file memory
    std::uint8_t memory_card_type = 0;      // 00 no memory card, 04 flash memory
    std::uint16_t memory_card_kbytes = 0;   // "0000 if there is no memory card"
    friend bool operator==(const CpuUnitAreaData&, const CpuUnitAreaData&) = default;
};

struct CpuUnitDataReadResponse {
    // Which parts are present: the request's selector (none = all).
    std::optional<CpuUnitDataSection> section;

    // Selector 00 / all.
    std::string model;           // trailing spaces stripped
    std::string system_version;  // trailing NULs stripped
    std::uint8_t dip_switch = 0;
    std::uint8_t largest_em_bank = 0;
    CpuUnitAreaData area;

    // Selector 01 / all.
    std::array<std::uint16_t, cpu_bus_unit_slots> bus_units{};  // cpu_bus_unit_present | ID
    std::uint8_t sysmac_bus_masters = 0;                        // remote I/O data, 00-02
    std::uint8_t racks = 0;                                     // CPU information bits 0-3

    [[nodiscard]] bool has_model_and_area() const noexcept {
        return section != CpuUnitDataSection::units_and_info;
    }
    [[nodiscard]] bool has_units_and_info() const noexcept {
        return section != CpuUnitDataSection::model_and_area;
    }
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const CpuUnitDataReadResponse&,
                           const CpuUnitDataReadResponse&) = default;
};

struct CpuUnitDataRead {
    static constexpr CommandCode code{0x05, 0x01};
    static constexpr std::string_view name = "CPU UNIT DATA READ";
    using Response = CpuUnitDataReadResponse;

    std::optional<CpuUnitDataSection> section;  // none: everything

    void encode(ByteWriter& w) const noexcept;
    // 0 or 1 byte; more: 1001; a selector other than 00/01: 110C.
    static Result<CpuUnitDataRead> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

// ---- 05 02 ----

inline constexpr std::uint8_t max_connection_items = 0x19;  // 5-3-16: 01-19 hex, default 19
inline constexpr std::size_t connection_model_size = 20;
inline constexpr std::uint8_t connection_last_unit = 0x80;  // bit 7 of "number of units"

struct ConnectionDataReadResponse {
    struct Unit {
        std::uint8_t unit_address = 0;
        std::string model;  // up to 20 ASCII characters; trailing spaces and NULs stripped
        friend bool operator==(const Unit&, const Unit&) = default;
    };
    bool last_unit_included = false;  // bit 7 of the count byte
    std::vector<Unit> units;          // at most 25

    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const ConnectionDataReadResponse&,
                           const ConnectionDataReadResponse&) = default;
};

struct ConnectionDataRead {
    static constexpr CommandCode code{0x05, 0x02};
    static constexpr std::string_view name = "CONNECTION DATA READ";
    using Response = ConnectionDataReadResponse;

    std::uint8_t first_unit = 0x00;     // 00 CPU Unit, 10-1F, 20-7F, E1
    std::optional<std::uint8_t> count;  // none: 19 hex (25)

    [[nodiscard]] std::uint8_t items() const noexcept {
        return count.value_or(max_connection_items);
    }
    void encode(ByteWriter& w) const noexcept;
    // 1 or 2 bytes. None: 1002; more: 1001; count 00 or above 19 hex: 110C.
    static Result<ConnectionDataRead> decode(Bytes parameters) noexcept;
    // Count byte then 21 bytes per unit, exactly; never more units than asked for.
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
