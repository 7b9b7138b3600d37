// CPU UNIT DATA READ 05 01 and CONNECTION DATA READ 05 02 (W342 5-3-15, 5-3-16;
// frames 6/0501, 6/0502).
#include "codec/command_codec.hpp"
#include "fins/commands/configuration.hpp"

namespace fins {

using codec::end_code;
using codec::malformed;

namespace {

// The CV-series 05 01 layout (Wireshark's dissector) has a 2-byte remote I/O field,
// "always 00" then the master count; clients accept it too.
constexpr std::size_t cv_remote_io_size = 2;
constexpr std::size_t connection_entry_size = 1 + connection_model_size;
constexpr std::size_t system_use_reserved = cpu_system_use_size - 2;
constexpr std::size_t bus_unit_reserved = cpu_bus_unit_block_size - 2 * cpu_bus_unit_slots;
constexpr std::uint8_t racks_mask = 0x0F;  // CPU information bits 0-3

void zeros(ByteWriter& w, std::size_t n) noexcept {
    w.text({}, n, 0x00);
}

// A fixed-width ASCII field without its padding (spaces or NULs).
std::string field_text(Bytes b) {
    std::size_t n = b.size();
    while (n > 0 && (b[n - 1] == 0x20 || b[n - 1] == 0x00))
        --n;
    return std::string(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n));
}

void write_area(ByteWriter& w, const CpuUnitAreaData& a) noexcept {
    w.u16(a.program_kwords);
    w.u8(a.iom_kbytes);
    w.u16(a.dm_words);
    w.u8(a.timer_counter_kwords);
    w.u8(a.em_non_file_banks);
    w.u16(0);  // bytes 7-8: not used by CS/CJ (CV: number of steps/transitions)
    w.u8(a.memory_card_type);
    w.u16(a.memory_card_kbytes);
}

CpuUnitAreaData read_area(ByteReader& r) noexcept {
    CpuUnitAreaData a;
    a.program_kwords = r.u16();
    a.iom_kbytes = r.u8();
    a.dm_words = r.u16();
    a.timer_counter_kwords = r.u8();
    a.em_non_file_banks = r.u8();
    r.skip(2);
    a.memory_card_type = r.u8();
    a.memory_card_kbytes = r.u16();
    return a;
}

void read_model_and_area(ByteReader& r, CpuUnitDataReadResponse& out) {
    out.model = field_text(r.bytes(cpu_model_size));
    out.system_version = field_text(r.bytes(cpu_version_size));
    out.dip_switch = r.u8();
    out.largest_em_bank = r.u8();
    r.skip(system_use_reserved);
    out.area = read_area(r);
}

// `remote_io` is 1 (W342 5-3-15, CS/CJ/CP) or 2 (CV series); CPU information is the
// last byte either way.
void read_units_and_info(ByteReader& r, CpuUnitDataReadResponse& out, std::size_t remote_io) {
    for (auto& unit : out.bus_units)
        unit = r.u16();
    r.skip(bus_unit_reserved);
    if (remote_io == cv_remote_io_size) r.skip(1);  // CV: "always 00"
    out.sysmac_bus_masters = r.u8();
    out.racks = static_cast<std::uint8_t>(r.u8() & racks_mask);
}

}  // namespace

void CpuUnitDataReadResponse::encode(ByteWriter& w) const noexcept {
    if (has_model_and_area()) {
        w.text(model, cpu_model_size, 0x20);
        w.text(system_version, cpu_version_size, 0x00);
        w.u8(dip_switch);
        w.u8(largest_em_bank);
        zeros(w, system_use_reserved);
        write_area(w, area);
    }
    if (has_units_and_info()) {
        for (auto unit : bus_units)
            w.u16(unit);
        zeros(w, bus_unit_reserved);
        w.u8(sysmac_bus_masters);  // remote I/O data: one byte (W342 5-3-15)
        w.u8(static_cast<std::uint8_t>(racks & racks_mask));
    }
}

void CpuUnitDataRead::encode(ByteWriter& w) const noexcept {
    if (section) w.u8(static_cast<std::uint8_t>(*section));
}

Result<CpuUnitDataRead> CpuUnitDataRead::decode(Bytes parameters) noexcept {
    if (parameters.size() > 1) return end_code(EndCode::command_too_long);
    CpuUnitDataRead c;
    if (parameters.empty()) return c;
    const auto selector = parameters[0];
    if (selector != static_cast<std::uint8_t>(CpuUnitDataSection::model_and_area) &&
        selector != static_cast<std::uint8_t>(CpuUnitDataSection::units_and_info))
        return end_code(EndCode::parameter_error);
    c.section = static_cast<CpuUnitDataSection>(selector);
    return c;
}

Result<CpuUnitDataRead::Response> CpuUnitDataRead::decode_response(Bytes data) const {
    Response out;
    out.section = section;
    std::size_t remote_io = cpu_remote_io_size;
    if (out.has_units_and_info()) {
        const std::size_t expected =
            (out.has_model_and_area() ? cpu_model_and_area_size : 0) + cpu_units_and_info_size;
        if (data.size() == expected + 1)
            remote_io = cv_remote_io_size;
        else if (data.size() != expected)
            return malformed();
    } else if (data.size() != cpu_model_and_area_size) {
        return malformed();
    }
    ByteReader r(data);
    if (out.has_model_and_area()) read_model_and_area(r, out);
    if (out.has_units_and_info()) read_units_and_info(r, out, remote_io);
    if (!r.complete()) return malformed();
    return out;
}

void ConnectionDataReadResponse::encode(ByteWriter& w) const noexcept {
    w.u8(static_cast<std::uint8_t>((units.size() & 0x7F) |
                                   (last_unit_included ? connection_last_unit : 0U)));
    for (const auto& unit : units) {
        w.u8(unit.unit_address);
        w.text(unit.model, connection_model_size, 0x20);
    }
}

void ConnectionDataRead::encode(ByteWriter& w) const noexcept {
    w.u8(first_unit);
    if (count) w.u8(*count);
}

Result<ConnectionDataRead> ConnectionDataRead::decode(Bytes parameters) noexcept {
    if (parameters.empty()) return end_code(EndCode::command_too_short);
    if (parameters.size() > 2) return end_code(EndCode::command_too_long);
    ConnectionDataRead c;
    c.first_unit = parameters[0];
    if (parameters.size() == 2) {
        const auto count = parameters[1];
        // 5-3-16: "Any number between 01 and 19 (hexadecimal) can be specified."
        if (count == 0 || count > max_connection_items) return end_code(EndCode::parameter_error);
        c.count = count;
    }
    return c;
}

Result<ConnectionDataRead::Response> ConnectionDataRead::decode_response(Bytes data) const {
    ByteReader r(data);
    const auto count_byte = r.u8();
    if (r.truncated()) return malformed();
    const std::size_t n = count_byte & 0x7FU;
    if (n > items() || r.remaining() != n * connection_entry_size) return malformed();
    Response out;
    out.last_unit_included = (count_byte & connection_last_unit) != 0;
    out.units.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        Response::Unit unit;
        unit.unit_address = r.u8();
        unit.model = field_text(r.bytes(connection_model_size));
        out.units.push_back(std::move(unit));
    }
    if (!r.complete()) return malformed();
    return out;
}

}  // namespace fins
