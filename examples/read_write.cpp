// Reads and writes a PLC's D area over FINS/UDP (or FINS/TCP with --tcp).
//   read_write [HOST] [PORT] [--tcp]
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <vector>

#include <fins/client.hpp>

int main(int argc, char** argv) {
    fins::ClientOptions options;
    if (argc > 1) options.host = argv[1];
    if (argc > 2) options.port = static_cast<std::uint16_t>(std::atoi(argv[2]));
    if (argc > 3 && std::string_view{argv[3]} == "--tcp")
        options.protocol = fins::ClientOptions::Protocol::tcp;

    auto client = fins::Client::connect(options);
    if (!client) {
        std::fprintf(stderr, "connect: %s\n", client.error().message().c_str());
        return 3;
    }
    const auto d100 = fins::parse_address("D100").value();
    const std::vector<std::uint16_t> words{1, 2, 3};
    if (auto w = (*client)->write_words(d100, words); !w) {
        std::fprintf(stderr, "write D100: %s\n", w.error().message().c_str());
        return 4;
    }
    auto r = (*client)->read_words(d100, 3);
    if (!r) {
        std::fprintf(stderr, "read D100: %s\n", r.error().message().c_str());
        return 4;
    }
    for (std::size_t i = 0; i < r->size(); ++i)
        std::printf("D%zu %u\n", 100 + i, (*r)[i]);
    if (auto f = (*client)->write_float(fins::parse_address("D200").value(), 1.5F); !f) return 4;
    const auto value = (*client)->read_float(fins::parse_address("D200").value());
    if (!value) return 4;
    std::printf("D200 %.1f\n", static_cast<double>(*value));
    return *r == words && *value == 1.5F ? 0 : 1;
}
