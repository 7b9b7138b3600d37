// A CPU Unit model as data: what the virtual PLC has and which memory area codes it
// accepts. Node-independent (the node address belongs to the network side).
//
// Sizes are the I/O memory sizes of W342 5-2-2 (CS/CJ mode). Region storage in
// IoMemory is allocated from these numbers; an address that the 5-2-2 table accepts
// but that lies beyond the profile's size answers like an address outside the area
// (1103 start / 1104 end).
#pragma once

#include <cstdint>
#include <string>

#include "fins/memory_area.hpp"

namespace fins::plc {

struct Profile {
    std::string model = "CJ2H-CPU68-EIP";

    // W342 5-2-2: EM banks 0x00-0x18 on the largest CS/CJ models; CJ2H-CPU68 has 25.
    std::uint8_t em_banks = 25;
    std::uint32_t em_bank_words = 32768;  // E n_00000-32767

    std::uint32_t cio_words = 6144;                 // CIO 0000-6143
    std::uint32_t work_words = 512;                 // W000-511
    std::uint32_t holding_words = 512;              // H000-511
    std::uint32_t auxiliary_words = 960;            // A000-959
    std::uint32_t auxiliary_read_only_words = 448;  // A000-447 are read-only (W342 5-2-2)
    std::uint32_t timers = 4096;                    // T0000-4095
    std::uint32_t counters = 4096;                  // C0000-4095
    std::uint32_t dm_words = 32768;                 // D00000-32767

    // W342 5-2-2 note 2: only CJ2 CPU Units accept 50-5F for EM banks 0-F.
    bool cj2_em_codes = true;
    // CS/CJ CPU Units accept the CVM1/CV-series codes of 5-2-2 (80, 82, 90-97 ...).
    bool cv_mode_codes = true;

    // True when this model accepts memory area code `segment.code` at all (1101 if not).
    [[nodiscard]] bool accepts(const MemoryAreaSegment& segment) const noexcept;
};

// CJ2H-CPU68-EIP: the default profile.
Profile cj2h();

}  // namespace fins::plc
