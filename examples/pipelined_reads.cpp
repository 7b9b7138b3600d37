// Keeps 32 one-word reads in flight at once (async_send, one service ID each) and
// waits for all of them with run(): the FINS client pipelines like an NX SendCmd.
//   pipelined_reads [HOST] [PORT]
#include <cstdio>
#include <cstdlib>

#include <fins/client.hpp>
#include <fins/commands/memory_area.hpp>

int main(int argc, char** argv) {
    fins::ClientOptions options;
    if (argc > 1) options.host = argv[1];
    if (argc > 2) options.port = static_cast<std::uint16_t>(std::atoi(argv[2]));
    auto client = fins::Client::connect(options);
    if (!client) {
        std::fprintf(stderr, "connect: %s\n", client.error().message().c_str());
        return 3;
    }
    constexpr int in_flight = 32;
    int ok = 0;
    int failed = 0;
    for (int i = 0; i < in_flight; ++i) {
        fins::Address address;  // D0, D1 ... D31
        address.area = fins::Area::dm;
        address.word = static_cast<std::uint16_t>(i);
        fins::MemoryAreaRead read;
        read.start = fins::to_memory_address(address).value();
        read.count = 1;
        (*client)->async_send(read, [&](fins::Result<fins::MemoryAreaReadResponse> r) {
            if (r) {
                ++ok;
            } else {
                ++failed;
                std::fprintf(stderr, "read: %s\n", r.error().message().c_str());
            }
        });
    }
    std::printf("in flight: %zu\n", (*client)->in_flight());
    (*client)->run();
    std::printf("completed %d, failed %d\n", ok, failed);
    return failed == 0 && ok == in_flight ? 0 : 1;
}
