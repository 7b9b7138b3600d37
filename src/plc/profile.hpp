// A CPU Unit model as data: what the virtual PLC has and which memory area codes it
// accepts. Node-independent (the node address belongs to the network side).
//
// Sizes are the I/O memory sizes of W342 5-2-2 (CS/CJ mode). Region storage in
// IoMemory is allocated from these numbers; an address that the 5-2-2 table accepts
// but that lies beyond the profile's size answers like an address outside the area
// (1103 start / 1104 end). An area the model does not have at all answers 1101.
//
// The registry (profiles(), find_profile()) holds the models finsd can be: see
// docs/finsd.md (Profiles) for the table and where each figure comes from.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fins/frame.hpp"

#include "fins/memory_area.hpp"

namespace fins::plc {

// A unit mounted with the CPU Unit, as 05 01 (CPU Bus Unit configuration) and 05 02
// (CONNECTION DATA READ) report it.
struct UnitInfo {
    std::uint8_t unit_address = 0;  // 10-1F CPU Bus Unit, 20-7F Special I/O Unit, E1 Inner Board
    std::string model;              // up to 20 ASCII characters
    std::uint16_t bus_unit_id = 0;  // 05 01 CPU Bus Unit model ID (bits 0-14); 0: not published
    std::string version = "V1.00";  // the unit's own 05 01 answer (W421 7-3-2 "Version")
};

// DIP switch pin 1 (UM write protection) in Profile::dip_switch: pin k is bit k-1.
inline constexpr std::uint8_t dip_pin1 = 0x01;

struct Profile {
    // Registry key (lower case, e.g. "cj2h"); also the identity of a state file
    // (Storage::open), so two profiles with different memory layouts never share one.
    std::string name = "cj2h";
    // The 05 01 model string as the unit answers it: CS1/CJ1/CP1 with an underscore
    // ("CJ1M_CPU13"), CJ2 with hyphens ("CJ2H-CPU65-EIP"); see profile.cpp.
    std::string model = "CJ2H-CPU68-EIP";
    std::string system_version = "01.90";  // 05 01 internal system version (20 ASCII)

    // 05 01 area data and CPU information (W342 5-3-15).
    // Program area size as 05 01 reports it, in K words: real units report twice the
    // catalogue K steps (CJ2H-CPU68-EIP, 400K steps: 800 = 0320 hex). Also the UM size
    // of 03 06..03 08 (program.hpp).
    std::uint16_t program_kwords = 800;
    std::uint8_t iom_kbytes = 23;           // I/O memory size in K bytes ("always 23")
    std::uint8_t timer_counter_kwords = 8;  // timer/counter size (x 1024, "always 8")
    std::uint8_t dip_switch = 0;            // pin k -> bit k-1 (pin 1 = UM write protection)
    // The Memory Card: none when memory_card_kbytes is 0 (05 01 then answers type 00,
    // size 0000, W342 5-3-15); otherwise its type (04 flash memory) and size in K bytes.
    std::uint8_t memory_card_type = 0x00;
    std::uint16_t memory_card_kbytes = 0;
    // A Memory Cassette (disk 8003) is mounted: the model answers 22 20 MEMORY CASSETTE
    // TRANSFER (W342 5-1-1: CP1H and CP1L only); other models answer it 0401.
    bool memory_cassette = false;
    std::uint8_t racks = 1;       // CPU Rack + expansion racks
    bool battery = true;          // 06 01 status bit 2
    std::vector<UnitInfo> units;  // mounted units, ascending unit address

    // The commands this model answers (MRC << 8 | SRC); empty = every command of the
    // W342 table. NX CPU Units answer only the W596 2-2 subset and 0401 for the rest.
    std::vector<std::uint16_t> commands;
    // NX CPU Units return the fixed 05 01 / 06 01 values of W596 2-2.
    bool nx_fixed_values = false;
    // A Loop Control Board is mounted (02 40 ITEM read, seed 001).
    bool loop_control = false;

    // W342 5-2-2: EM banks 0x00-0x18 on the largest CS/CJ models; CJ2H-CPU68 has 25.
    std::uint8_t em_banks = 25;
    std::uint32_t em_bank_words = 32768;  // E n_00000-32767
    // PLC Setup "EM file memory": banks from this one on are EM file memory (disk 8001,
    // W342 5-3-35); >= em_banks: none. 05 01 reports the banks before it as non-file EM.
    std::uint8_t em_file_bank = 0xFF;

    std::uint32_t cio_words = 6144;                 // CIO 0000-6143
    std::uint32_t work_words = 512;                 // W000-511
    std::uint32_t holding_words = 512;              // H000-511
    std::uint32_t auxiliary_words = 960;            // A000-959; 0 = no Auxiliary Area
    std::uint32_t auxiliary_read_only_words = 448;  // A000-447 are read-only (W342 5-2-2)
    std::uint32_t timers = 4096;                    // T0000-4095; 0 = no timers
    std::uint32_t counters = 4096;                  // C0000-4095; 0 = no counters
    std::uint32_t dm_words = 32768;                 // D00000-32767

    // W342 5-2-2 note 2: only CJ2 CPU Units accept 50-5F for EM banks 0-F.
    bool cj2_em_codes = true;
    // CS/CJ CPU Units accept the CVM1/CV-series codes of 5-2-2 (80, 82, 90-97 ...).
    bool cv_mode_codes = true;
    // The CPU Unit's own areas: task flags (06, 46), IR/DR (DC, BC, 9C), clock pulses,
    // condition flags and the access error flag (07), the EM current bank (0A, 98,
    // BC 0F00). NX CPU Units have none of them (W596 2-2: "only areas that exist in
    // the memory of CJ-series Units": CIO, WR, HR, DM, EM).
    bool cpu_areas = true;

    // True when this model accepts memory area code `segment.code` at all (1101 if not).
    [[nodiscard]] bool accepts(const MemoryAreaSegment& segment) const noexcept;
    // True when this model answers `code` (else 0401 undefined command).
    [[nodiscard]] bool supports(CommandCode code) const noexcept;
    // The mounted unit at `unit_address` (a unit 05 02 lists), or nullptr.
    [[nodiscard]] const UnitInfo* unit(std::uint8_t unit_address) const noexcept;
    // 05 01 memory card fields: type 00 and size 0000 without a card (W342 5-3-15).
    [[nodiscard]] bool has_memory_card() const noexcept {
        return memory_card_type != 0 && memory_card_kbytes != 0;
    }
};

// Every profile finsd knows, CJ2H first (the default).
std::span<const Profile> profiles() noexcept;
// The profile whose name or model equals `name`, ignoring case and taking '-' and '_'
// as the same ("cj2h", "CJ2H-CPU68-EIP", "CJ1M-CPU13" = "CJ1M_CPU13", "nx102-9000" ...);
// nullptr when there is none.
const Profile* find_profile(std::string_view name) noexcept;

// CJ2H-CPU68-EIP: the default profile.
Profile cj2h();

}  // namespace fins::plc
