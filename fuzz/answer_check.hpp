// Shared by the dispatcher fuzz targets: what every answer the dispatcher writes must be.
#pragma once

#include <cstdlib>

#include "fins/byte_io.hpp"
#include "fins/frame.hpp"

namespace fins_fuzz {

// A decodable response frame that fits a FINS frame and echoes the request's SID and
// command code. Only the request's header and command code are known to be there (an
// oversized frame is answered 1001 without being decoded). Aborts otherwise.
inline void check_answer(fins::Bytes request, fins::Bytes answer) {
    if (answer.size() > fins::max_frame_size) std::abort();
    auto response = fins::decode_response(answer);
    if (!response) std::abort();
    fins::ByteReader r{request};
    const auto header = fins::read_header(r);
    const fins::CommandCode command{r.u8(), r.u8()};
    if (r.truncated() || response->header.service_id != header.service_id) std::abort();
    if (!(response->command == command)) std::abort();
}

}  // namespace fins_fuzz
