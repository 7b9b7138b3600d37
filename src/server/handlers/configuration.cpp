// 05 xx machine configuration reading: CPU UNIT DATA READ 05 01, CONNECTION DATA READ
// 05 02 (W342 5-3-15, 5-3-16). Everything comes from the Profile; both are accepted in
// every mode and under every protection (5-1-2).
//
// 05 01 sent to a CPU Bus Unit the profile lists (unit address 10-1F, dispatcher.cpp)
// is that unit's own CONTROLLER DATA READ (Ethernet Units, W421 7-3-2): model and
// version (20 ASCII characters each, space padded), IP address, subnet mask, FINS UDP
// port number, mode setting, Ethernet address = 58 bytes; any parameter is 1001.
// finsd does not model the unit's network settings: IP address, subnet mask and
// Ethernet address are 0, the port is the default 9600 and the mode setting 0000
// ("default" port, automatic address generation).
#include <algorithm>
#include <optional>

#include "fins/commands/configuration.hpp"
#include "plc/plc.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::server::handlers {

namespace {

constexpr std::uint8_t first_bus_unit = 0x10;  // CPU Bus Unit n = 10 + n (frames 1.4)
constexpr std::uint8_t last_bus_unit = 0x1F;
constexpr std::uint16_t bus_unit_id_mask = 0x7FFF;
// DIP switch pin 1 (UM write protection) is bit 0 of the DIP switch byte.
constexpr std::uint8_t dip_pin1_bit = 0x01;

// W596 2-2 *1: fixed values an NX CPU Unit returns in 05 01.
constexpr std::uint16_t nx_program_kwords = 0x0014;
constexpr std::uint8_t nx_timer_counter_kwords = 0x08;
constexpr std::uint8_t nx_memory_card_type = 0x04;  // SD Memory Card, present or not
constexpr std::uint16_t nx_card_inserted_size = 0xFFFF;

// W421 7-3-2: a CPU Bus Unit's CONTROLLER DATA READ answer after model and version.
constexpr std::size_t unit_address_bytes = 4;  // IP address, then subnet mask
constexpr std::uint16_t unit_fins_udp_port = 9600;
constexpr std::size_t unit_ethernet_address_bytes = 6;

CpuUnitDataReadResponse cpu_unit_data(const plc::Plc& plc,
                                      std::optional<CpuUnitDataSection> section) {
    const auto& p = plc.profile();
    CpuUnitDataReadResponse r;
    r.section = section;
    r.model = p.model;
    r.system_version = p.system_version;
    r.dip_switch = p.dip_switch;
    if (plc.dip_write_protection()) r.dip_switch |= dip_pin1_bit;
    r.largest_em_bank = p.em_banks == 0 ? 0 : static_cast<std::uint8_t>(p.em_banks - 1);
    r.area.program_kwords = p.program_kwords;
    r.area.iom_kbytes = p.iom_kbytes;
    r.area.dm_words = static_cast<std::uint16_t>(p.dm_words > 0xFFFF ? 0xFFFF : p.dm_words);
    r.area.timer_counter_kwords = p.timer_counter_kwords;
    r.area.em_non_file_banks = plc.files().em_non_file_banks();
    // W342 5-3-15: the card as inserted now (finsd ctl card insert/remove): no card =
    // type 00 and size 0000; a card = its type (04 flash when the profile names none)
    // and its size in KB.
    const std::uint32_t card_kb = plc.files().card_kbytes();
    r.area.memory_card_type =
        card_kb == 0 ? std::uint8_t{0x00}
                     : (p.memory_card_type != 0 ? p.memory_card_type : std::uint8_t{0x04});
    r.area.memory_card_kbytes = static_cast<std::uint16_t>(std::min<std::uint32_t>(card_kb, 0xFFFF));
    for (const auto& unit : p.units) {
        if (unit.unit_address < first_bus_unit || unit.unit_address > last_bus_unit) continue;
        r.bus_units[unit.unit_address - first_bus_unit] = static_cast<std::uint16_t>(
            cpu_bus_unit_present | (unit.bus_unit_id & bus_unit_id_mask));
    }
    r.sysmac_bus_masters = 0;  // no SYSMAC BUS Remote I/O Master Units
    r.racks = p.racks;
    if (p.nx_fixed_values) {
        r.dip_switch = 0;
        r.area.program_kwords = nx_program_kwords;
        r.area.timer_counter_kwords = nx_timer_counter_kwords;
        r.area.memory_card_type = nx_memory_card_type;
        r.area.memory_card_kbytes = plc.files().card_inserted() ? nx_card_inserted_size : 0;
        r.sysmac_bus_masters = 0;
    }
    return r;
}

// The unit with the lowest address >= `from`: the CPU Unit (00, the profile's model)
// or a unit of the profile. nullopt when there is none.
struct Found {
    std::uint8_t address;
    const std::string* model;
};
std::optional<Found> unit_at_or_after(const plc::Profile& p, unsigned from) {
    std::optional<Found> best;
    if (from == 0) best = Found{cpu_unit, &p.model};
    for (const auto& unit : p.units) {
        if (unit.unit_address == cpu_unit || unit.unit_address < from) continue;
        if (!best || unit.unit_address < best->address)
            best = Found{unit.unit_address, &unit.model};
    }
    return best;
}

// W421 7-3-2 (see the top of this file).
EndCode unit_controller_data(const plc::UnitInfo& unit, const CpuUnitDataRead& command,
                             ByteWriter& out) {
    if (command.section) return EndCode::command_too_long;
    out.text(unit.model, cpu_model_size, 0x20);
    out.text(unit.version, cpu_version_size, 0x20);
    out.text({}, 2 * unit_address_bytes, 0x00);
    out.u16(unit_fins_udp_port);
    out.u16(0x0000);  // mode setting
    out.text({}, unit_ethernet_address_bytes, 0x00);
    return EndCode::normal_completion;
}

}  // namespace

// W342 5-3-15. Selector 00: model .. area data; 01: CPU Bus Units .. CPU information;
// none: all (158 data bytes: the remote I/O data is "a single byte").
EndCode execute(HandlerContext& context, const CpuUnitDataRead& command, ByteWriter& out) {
    const auto unit = context.header.destination.unit;
    if (unit != cpu_unit) {
        const plc::UnitInfo* info = context.plc.profile().unit(unit);
        // The dispatcher routes only listed CPU Bus Units here.
        if (info == nullptr) return EndCode::unit_missing;
        return unit_controller_data(*info, command, out);
    }
    cpu_unit_data(context.plc, command.section).encode(out);
    return EndCode::normal_completion;
}

// W342 5-3-16. Units in ascending unit address from the first one at or after the
// requested address ("if the specified Unit does not exist, the connection data is read
// from the next Unit"); bit 7 of the count when the last unit is in the answer. Past
// the last unit: no units, count byte 80.
EndCode execute(HandlerContext& context, const ConnectionDataRead& command, ByteWriter& out) {
    const auto& p = context.plc.profile();
    ConnectionDataReadResponse r;
    unsigned next = command.first_unit;
    bool more = true;
    while (r.units.size() < command.items()) {
        const auto found = unit_at_or_after(p, next);
        if (!found) {
            more = false;
            break;
        }
        r.units.push_back({found->address, *found->model});
        next = found->address + 1U;
    }
    if (more) more = next <= 0xFF && unit_at_or_after(p, next).has_value();
    r.last_unit_included = !more;
    r.encode(out);
    return EndCode::normal_completion;
}

namespace {
constexpr HandlerEntry table[] = {entry<CpuUnitDataRead>(), entry<ConnectionDataRead>()};
}  // namespace

std::span<const HandlerEntry> configuration_handlers() noexcept {
    return table;
}

}  // namespace fins::server::handlers
