// The profile registry. Each profile fact cites where it comes from:
//
//   [W342]   W342 5-3-15 (seed 000): the 05 01 fields ("IOM size ... always 23",
//            "Number of DM words ... always 32,768", "Timer/counter size ... always 8",
//            "Memory card type 00: No memory card 04: Flash memory", "Memory card size
//            ... 0000 if there is no memory card").
//   [W596]   W596 2-2 (seed 002): the NX fixed 05 01 values and command subset.
//   [LF]     libfins, lammertb/libfins src/fins_model_list.c: model strings as CPU Units
//            answer 05 01 ("CJ1M_CPU13", "CS1H_CPU67H", "CP1H_XA40DR-A"), program
//            capacity in steps and EM banks per model ("CJ2H_CPU68-EIP" 400000 steps,
//            25 banks; "CJ2H_CPU67-EIP" 250000, 15; "CS1H_CPU67H" 250000, 13;
//            "CJ1M_CPU13" 20000, 0; "CP1H_XA40DR-A" 20000, 0).
//   [SCAN]   05 01 answers of real units published with scanners: nmap's
//            scripts/omron-info.nse (nmap/nmap) shows a CJ2M-CPU32 (10K steps) answering
//            "CJ2M-CPU32", "02.01", program area size 20; a public scan of a
//            CJ2H-CPU65-EIP (100K steps) shows "CJ2H-CPU65-EIP", "01.90", program area
//            size 200 (00C8), EM 4 banks, no memory card (type 0, size 0); ICS scanner
//            examples show a CJ1M (20K steps) answering "CJ1M_CPU13", "04.10", program
//            area size 40 (0028), no memory card. So: the program area size is twice the
//            catalogue K steps, CJ2 model strings keep their hyphens (libfins' own
//            "CJ2H_CPU68-EIP" spelling is not what the units send), and CJ2 versions are
//            1.x (CJ2H) / 2.x (CJ2M).
//   [W421]   CS1W-ETN21/CJ1W-ETN21 Ethernet Units manual 7-3-2: a CPU Bus Unit's own
//            05 01 answer (model, version "V1.20" in its example).
// Figures no source above gives are choices, marked "choice" (docs/finsd.md, Profiles).
#include "plc/profile.hpp"

#include <array>
#include <cstddef>

namespace fins::plc {

namespace {

// W342 5-2-2 note 2: 50-5F are the CJ2-only alternative codes for EM bank 0-F words.
constexpr bool is_cj2_em_code(std::uint8_t code) noexcept {
    return code >= 0x50 && code <= 0x5F;
}

// Storage index of counter C0000 in the timer/counter region (io_memory.hpp
// counter_base): counter segments of 5-2-2 start there.
constexpr std::uint16_t first_counter_index = 4096;

bool is_cpu_area(Region region) noexcept {
    switch (region) {
        case Region::task_flag:
        case Region::index_register:
        case Region::data_register:
        case Region::clock_pulse:
        case Region::condition_flag:
        case Region::access_error_flag:
        case Region::em_current:
        case Region::em_bank_number:
            return true;
        default:
            return false;
    }
}

char lower(char c) noexcept {
    return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
}

// '-' and '_' are the same: "CJ1M-CPU13" (catalogue) finds "CJ1M_CPU13" (05 01 answer).
char fold(char c) noexcept {
    return c == '_' ? '-' : lower(c);
}

bool same_ignoring_case(std::string_view a, std::string_view b) noexcept {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (fold(a[i]) != fold(b[i])) return false;
    return true;
}

// CJ2H-CPU68-EIP: 400K steps [LF] -> program area 800 K words (0320) [SCAN]; DM 32K,
// EM 32K x 25 banks E00-E18 [LF]; version "01.90" as the CJ2H-CPU65-EIP answers [SCAN];
// a 30 MB flash Memory Card inserted (a choice, so the 22 xx file commands work out of
// the box; the scanned CJ2H had none [SCAN]). Its built-in EtherNet/IP port is
// CPU Bus Unit 0 (unit address 10); the name "CJ2B-EIP21" is a choice.
Profile make_cj2h() {
    Profile p;
    p.model = "CJ2H-CPU68-EIP";
    p.system_version = "01.90";
    p.program_kwords = 800;
    p.em_banks = 25;
    p.memory_card_type = 0x04;
    p.memory_card_kbytes = 30720;
    p.units = {UnitInfo{0x10, "CJ2B-EIP21", 0, "V2.00"}};
    return p;
}

// CS1H-CPU67H: "CS1H_CPU67H" [LF], 250K steps -> 500 K words (01F4), EM 13 banks E0-EC
// [LF], no CJ2 codes [W342 5-2-2 note 2]. Choices: version "04.00" (CS1-H unit version
// 4.0), an Ethernet Unit at unit 0 and a 30 MB flash Memory Card (HMC-EF372: type 04,
// 30,720 K bytes).
Profile make_cs1h() {
    Profile p;
    p.name = "cs1h";
    p.model = "CS1H_CPU67H";
    p.system_version = "04.00";
    p.program_kwords = 500;
    p.em_banks = 13;
    p.cj2_em_codes = false;
    p.memory_card_type = 0x04;
    p.memory_card_kbytes = 30720;
    p.units = {UnitInfo{0x10, "CS1W-ETN21", 0, "V1.20"}};
    return p;
}

// The same CS1H with a CS1W-LCB05 Loop Control Board as its Inner Board (unit E1).
Profile make_cs1h_lcb() {
    Profile p = make_cs1h();
    p.name = "cs1h-lcb";
    p.loop_control = true;
    p.units.push_back(UnitInfo{0xE1, "CS1W-LCB05", 0, "V1.00"});
    return p;
}

// CJ1M-CPU13: "CJ1M_CPU13", version "04.10", program area 40 K words (0028), no memory
// card [SCAN]; 20K steps, no EM [LF]. A CJ1W-ETN21 at unit 0 is a choice.
Profile make_cj1m() {
    Profile p;
    p.name = "cj1m";
    p.model = "CJ1M_CPU13";
    p.system_version = "04.10";
    p.program_kwords = 40;
    p.em_banks = 0;
    p.cj2_em_codes = false;
    p.memory_card_type = 0x00;
    p.memory_card_kbytes = 0;
    p.units = {UnitInfo{0x10, "CJ1W-ETN21", 0, "V1.20"}};
    return p;
}

// CP1H-XA40DR-A: "CP1H_XA40DR-A", 20K steps -> 40 K words (0028), no EM [LF]. It has a
// Memory Cassette rather than a Memory Card: 05 01 reports no card (type 00, 0000).
// Choices: version "01.00"; a CJ1W-ETN21 through the CP1W-EXT01 CJ Unit Adapter at
// unit 0; CS/CJ-mode codes only (no CV-mode codes); a Memory Cassette mounted (22 20).
Profile make_cp1h() {
    Profile p;
    p.name = "cp1h";
    p.model = "CP1H_XA40DR-A";
    p.system_version = "01.00";
    p.program_kwords = 40;
    p.em_banks = 0;
    p.cj2_em_codes = false;
    p.cv_mode_codes = false;
    p.memory_card_type = 0x00;
    p.memory_card_kbytes = 0;
    p.memory_cassette = true;
    p.units = {UnitInfo{0x10, "CJ1W-ETN21", 0, "V1.20"}};
    return p;
}

// NX102-9000 [W596 2-2]: the FINS subset, CJ-compatible areas only (CIO 6144, WR 512,
// HR 512 = what the 5-2-2 table addresses, DM 32K, EM 4 banks: a choice), fixed
// 05 01 values (program area 14 hex, timer/counter 08, SD card type 04 and size FFFF
// with a card, 0 without), no battery bit, no units reported. Version "01.40": choice.
Profile make_nx102() {
    Profile p;
    p.name = "nx102";
    p.model = "NX102-9000";
    p.system_version = "01.40";
    p.program_kwords = 0x14;
    p.memory_card_type = 0x04;
    p.memory_card_kbytes = 0;
    p.battery = false;
    p.commands = {0x0101, 0x0102, 0x0103, 0x0104, 0x0105, 0x0501, 0x0601, 0x0701, 0x0702};
    p.nx_fixed_values = true;
    p.em_banks = 4;
    p.auxiliary_words = 0;
    p.auxiliary_read_only_words = 0;
    p.timers = 0;
    p.counters = 0;
    p.cj2_em_codes = false;
    p.cv_mode_codes = false;
    p.cpu_areas = false;
    return p;
}

const std::array<Profile, 6>& registry() {
    static const std::array<Profile, 6> all{make_cj2h(), make_cs1h(), make_cs1h_lcb(),
                                            make_cj1m(), make_cp1h(), make_nx102()};
    return all;
}

}  // namespace

bool Profile::accepts(const MemoryAreaSegment& segment) const noexcept {
    if (segment.cv_mode && !cv_mode_codes) return false;
    if (is_cj2_em_code(segment.code) && !cj2_em_codes) return false;
    if (!cpu_areas && is_cpu_area(segment.region)) return false;
    switch (segment.region) {
        case Region::em:
            return segment.em_bank < em_banks;
        case Region::em_current:
        case Region::em_bank_number:
            return em_banks != 0;
        case Region::auxiliary:
            return auxiliary_words != 0;
        case Region::timer_counter:
            return (segment.region_offset >= first_counter_index ? counters : timers) != 0;
        default:
            return true;
    }
}

bool Profile::supports(CommandCode code) const noexcept {
    if (code == CommandCode{0x22, 0x20} && !memory_cassette) return false;
    if (commands.empty()) return true;
    for (auto c : commands)
        if (c == code.value()) return true;
    return false;
}

const UnitInfo* Profile::unit(std::uint8_t unit_address) const noexcept {
    for (const auto& u : units)
        if (u.unit_address == unit_address) return &u;
    return nullptr;
}

std::span<const Profile> profiles() noexcept {
    return registry();
}

const Profile* find_profile(std::string_view name) noexcept {
    for (const auto& p : registry())
        if (same_ignoring_case(name, p.name) || same_ignoring_case(name, p.model)) return &p;
    return nullptr;
}

Profile cj2h() {
    return registry().front();
}

}  // namespace fins::plc
