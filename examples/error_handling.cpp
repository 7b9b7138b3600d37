// Every failure is a std::error_code: a FINS end code from the PLC (category
// "fins.end_code", compare with fins::EndCode), or a local failure (fins::ClientError:
// timeout, connection closed ...). This program provokes three and tells them apart.
//   error_handling [HOST] [PORT]
#include <cstdio>
#include <cstdlib>
#include <system_error>

#include <fins/client.hpp>

namespace {

void explain(const char* what, const std::error_code& ec) {
    if (ec.category() == fins::end_code_category()) {
        // The PLC answered: the end code's name and probable cause (W342 5-1-3).
        const auto* info = fins::find_end_code(static_cast<std::uint16_t>(ec.value()));
        std::printf("%s: end code %04X %s\n", what, static_cast<unsigned>(ec.value()),
                    info ? std::string(info->name).c_str() : ec.message().c_str());
    } else if (ec == fins::ClientError::timeout) {
        std::printf("%s: no answer (timeout)\n", what);
    } else {
        std::printf("%s: %s [%s]\n", what, ec.message().c_str(), ec.category().name());
    }
}

}  // namespace

int main(int argc, char** argv) {
    fins::ClientOptions options;
    if (argc > 1) options.host = argv[1];
    if (argc > 2) options.port = static_cast<std::uint16_t>(std::atoi(argv[2]));
    options.timeout = std::chrono::milliseconds{300};
    auto client = fins::Client::connect(options);
    if (!client) {
        explain("connect", client.error());
        return 3;
    }
    int seen = 0;
    // A bad address string never reaches the wire.
    if (auto a = fins::parse_address("D99999"); !a) {
        explain("parse D99999", a.error());
        ++seen;
    }
    // A000-A447 are read-only: the CPU Unit answers 2101.
    const std::uint16_t one = 1;
    if (auto w = (*client)->write_words(fins::parse_address("A10").value(), {&one, 1}); !w) {
        explain("write A10", w.error());
        if (w.error() == fins::EndCode::read_only) ++seen;
    }
    // A read past the end of the D area: 1104 (address range exceeded).
    if (auto r = (*client)->read_words(fins::parse_address("D32760").value(), 20); !r) {
        explain("read D32760 x20", r.error());
        if (r.error().category() == fins::end_code_category()) ++seen;
    }
    std::printf("%d errors recognised\n", seen);
    return seen == 3 ? 0 : 1;
}
