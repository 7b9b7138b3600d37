// The profile registry. Figures are Omron catalogue figures as recalled for each model
// (README (profiles and configuration) says which are choices rather than catalogue data).
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

bool same_ignoring_case(std::string_view a, std::string_view b) noexcept {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (lower(a[i]) != lower(b[i])) return false;
    return true;
}

// CJ2H-CPU68-EIP: 250K steps, DM 32K, EM 32K x 25 banks (E00-E18), built-in
// EtherNet/IP port = CPU Bus Unit 0 (unit address 10); a Memory Card inserted.
Profile make_cj2h() {
    Profile p;
    // A 30 MB flash Memory Card is inserted, so the 22 xx commands work out of the box.
    p.memory_card_kbytes = 30720;
    p.units = {UnitInfo{0x10, "CJ2B-EIP21", 0}};
    return p;
}

// CS1H-CPU67H: 250K steps, DM 32K, EM 32K x 13 banks (E0-EC), no CJ2 codes; an
// Ethernet Unit at unit 0 and a 30 MB flash Memory Card (HMC-EF372).
Profile make_cs1h() {
    Profile p;
    p.name = "cs1h";
    p.model = "CS1H-CPU67H";
    p.system_version = "04.00";
    p.em_banks = 13;
    p.cj2_em_codes = false;
    p.memory_card_type = 0x04;
    p.memory_card_kbytes = 30720;
    p.units = {UnitInfo{0x10, "CS1W-ETN21", 0}};
    return p;
}

// The same CS1H with a CS1W-LCB05 Loop Control Board as its Inner Board (unit E1).
Profile make_cs1h_lcb() {
    Profile p = make_cs1h();
    p.name = "cs1h-lcb";
    p.loop_control = true;
    p.units.push_back(UnitInfo{0xE1, "CS1W-LCB05", 0});
    return p;
}

// CJ1M-CPU13: 20K steps, DM 32K, no EM, no Memory Card; a CJ1W-ETN21 at unit 0.
Profile make_cj1m() {
    Profile p;
    p.name = "cj1m";
    p.model = "CJ1M-CPU13";
    p.system_version = "04.00";
    p.program_kwords = 20;
    p.em_banks = 0;
    p.cj2_em_codes = false;
    p.memory_card_type = 0x00;
    p.units = {UnitInfo{0x10, "CJ1W-ETN21", 0}};
    return p;
}

// CP1H-XA40DR-A: 20K steps, DM 32K, no EM, a Memory Cassette rather than a card, a
// CJ1W-ETN21 through the CP1W-EXT01 CJ Unit Adapter at unit 0. Choice: CS/CJ-mode
// codes only (no CV-mode codes).
Profile make_cp1h() {
    Profile p;
    p.name = "cp1h";
    p.model = "CP1H-XA40DR-A";
    p.system_version = "01.00";
    p.program_kwords = 20;
    p.em_banks = 0;
    p.cj2_em_codes = false;
    p.cv_mode_codes = false;
    p.memory_card_type = 0x00;
    p.units = {UnitInfo{0x10, "CJ1W-ETN21", 0}};
    return p;
}

// NX102-9000 (W596 2-2): the FINS subset, CJ-compatible areas only (CIO 6144, WR 512,
// HR 512 = what the 5-2-2 table addresses, DM 32K, EM 4 banks: a choice), fixed
// 05 01 values (program area 14 hex, timer/counter 08, SD card type 04), no battery
// bit, no units reported.
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
    if (commands.empty()) return true;
    for (auto c : commands)
        if (c == code.value()) return true;
    return false;
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
