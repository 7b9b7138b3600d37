// `fins files save / load / compare` (22 0A / 0B / 0C) helpers, in
// verbs_files_transfer.cpp; the verbs themselves are in verbs_files.cpp.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "fins/address.hpp"
#include "fins/client.hpp"
#include "fins/commands/file_memory.hpp"
#include "fins/commands/parameter_area.hpp"

namespace fins::cli {

struct TransferArguments {
    std::string plc, what;
    unsigned count = 0;
    std::string problem;  // the usage message when the list does not fit
};
// `save WHAT PLCFILE [COUNT]`, `save WHAT COUNT PLCFILE` (docs/file-memory.md's "D100 10"),
// `load|compare PLCFILE WHAT [COUNT]`; anything else: a usage message naming the form.
TransferArguments transfer_arguments(FileTransferMode mode, const std::vector<std::string>& v);

// What `files compare` compared the file with.
struct CompareTarget {
    enum class Kind { words, parameters, program } kind = Kind::words;
    Address start;                            // words
    std::size_t count = 0;                    // words
    const ParameterAreaInfo* area = nullptr;  // parameters
};
// After a compare answered 2007: "3 of 10 words differ; the first is D103: file 1234,
// PLC 0000" (and a length difference), or why it could not be found out.
std::string describe_file_difference(Client& client, std::uint16_t disk,
                                     const std::string& directory, const FileName& file,
                                     const CompareTarget& target);

}  // namespace fins::cli
