// fuzz_make_corpus DUMP VECTORS OUT: turns the test traffic dumped with FINS_FUZZ_DUMP
// (corpus_dump.hpp: DUMP/request, DUMP/response, DUMP/tcp_stream) and the golden vectors
// (tests/vectors/*.txt) into candidate seeds, OUT/<target>/<hash>, in each target's
// input format. fuzz/make_corpus.sh then keeps those that add coverage (-merge=1).
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "corpus_dump.hpp"
#include "fins/tcp.hpp"

namespace {

namespace fs = std::filesystem;
using Blob = std::vector<std::uint8_t>;

std::vector<Blob> read_all(const fs::path& dir) {
    std::vector<Blob> out;
    if (!fs::is_directory(dir)) return out;
    for (const auto& e : fs::directory_iterator(dir)) {
        std::ifstream in(e.path(), std::ios::binary);
        out.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    return out;
}

// Data lines of a vector file (hex bytes, '#' comments), or the first word of each line
// (address_examples.txt).
std::vector<std::string> vector_lines(const fs::path& file) {
    std::vector<std::string> out;
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && line[0] != '#') out.push_back(line);
    return out;
}

Blob hex(const std::string& text) {
    Blob out;
    int high = -1;
    for (char c : text) {
        int v = -1;
        if (c >= '0' && c <= '9') v = c - '0';
        if (c >= 'A' && c <= 'F') v = c - 'A' + 10;
        if (c >= 'a' && c <= 'f') v = c - 'a' + 10;
        if (v < 0) continue;
        if (high < 0) {
            high = v;
        } else {
            out.push_back(static_cast<std::uint8_t>(high * 16 + v));
            high = -1;
        }
    }
    return out;
}

class Out {
  public:
    explicit Out(fs::path root) : root_(std::move(root)) {}
    void add(const char* target, const Blob& b) {
        if (b.empty()) return;
        // corpus_dump.hpp names files by content: the same seed is written once.
        ::setenv("FINS_FUZZ_DUMP", root_.c_str(), 1);
        fins::fuzz::dump_test_bytes(target, b);
        ++count_;
    }
    [[nodiscard]] std::size_t count() const { return count_; }

  private:
    fs::path root_;
    std::size_t count_ = 0;
};

Blob tcp_frame(const Blob& frame) {
    Blob out(fins::tcp_header_size + frame.size());
    fins::ByteWriter w{out};
    fins::write_tcp_header(w, fins::TcpCommand::frame, frame.size());
    w.bytes(frame);
    return out;
}

Blob handshake() {
    Blob out(20);
    fins::ByteWriter w{out};
    fins::write_node_address_request(w, 0);
    return out;
}

void append(Blob& to, const Blob& b) {
    to.insert(to.end(), b.begin(), b.end());
}

// fuzz_session's record: kind (even: datagram, odd: TCP chunk), 16-bit length, bytes.
void record(Blob& to, std::uint8_t kind, const Blob& b) {
    to.push_back(kind);
    to.push_back(static_cast<std::uint8_t>(b.size() >> 8));
    to.push_back(static_cast<std::uint8_t>(b.size()));
    append(to, b);
}

// The server tests address a CPU Unit at network 1, node 0x0A from network 1, node
// 0x14 (tests/server/frame_builder.hpp); the fuzz targets serve network 0, node 1, and
// a FINS/TCP client is node 239 (the first one allocated). Other addresses, the ones
// tests use to be refused, stay as they are.
Blob retarget(Blob frame, std::uint8_t source_node) {
    if (frame.size() < fins::header_size) return frame;
    if (frame[3] == 0x01) frame[3] = 0x00;  // DNA
    if (frame[4] == 0x0A) frame[4] = 0x01;  // DA1
    if (frame[6] == 0x01) frame[6] = 0x00;  // SNA
    if (frame[7] == 0x14) frame[7] = source_node;
    return frame;
}

void add_request(Out& out, const Blob& test_frame) {
    out.add("fuzz_frame", test_frame);
    const Blob frame = retarget(test_frame, 0x14);
    out.add("fuzz_dispatch", frame);
    const Blob tcp_client_frame = retarget(test_frame, 0xEF);
    Blob stream = handshake();
    append(stream, tcp_frame(tcp_client_frame));
    out.add("fuzz_tcp", stream);
    Blob udp{0};
    record(udp, 0, frame);
    out.add("fuzz_session", udp);
    // Over TCP after the automatic handshake, cut in two at the middle of the packet.
    const Blob packet = tcp_frame(tcp_client_frame);
    const auto half = static_cast<std::ptrdiff_t>(packet.size() / 2);
    Blob tcp{0};
    record(tcp, 1, Blob(packet.begin(), packet.begin() + half));
    record(tcp, 1, Blob(packet.begin() + half, packet.end()));
    out.add("fuzz_session", tcp);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: fuzz_make_corpus DUMP VECTORS OUT\n");
        return 2;
    }
    const fs::path dump = argv[1];
    const fs::path vectors = argv[2];
    Out out{argv[3]};

    for (const auto& frame : read_all(dump / "request"))
        add_request(out, frame);
    for (const auto& frame : read_all(dump / "response"))
        out.add("fuzz_frame", frame);
    for (const auto& stream : read_all(dump / "tcp_stream")) {
        out.add("fuzz_tcp", stream);
        Blob session{1};  // the stream carries its own handshake
        record(session, 1, stream);
        out.add("fuzz_session", session);
    }

    // Golden vectors: frames, a command with its parameters, FINS/TCP packets, addresses.
    for (const auto& line : vector_lines(vectors / "memory_area_read_d10_frame.txt")) {
        out.add("fuzz_frame", hex(line));
        out.add("fuzz_dispatch", hex(line));
    }
    for (const auto& line : vector_lines(vectors / "memory_area_read_d10.txt")) {
        Blob frame = hex("80 00 02 00 01 00 00 0A 00 12");
        append(frame, hex(line));
        add_request(out, frame);
    }
    Blob all_tcp;
    for (const auto& line : vector_lines(vectors / "tcp_handshake.txt")) {
        out.add("fuzz_tcp", hex(line));
        append(all_tcp, hex(line));
    }
    out.add("fuzz_tcp", all_tcp);
    for (const auto& line : vector_lines(vectors / "address_examples.txt")) {
        const auto word = line.substr(0, line.find(' '));
        out.add("fuzz_address", Blob(word.begin(), word.end()));
    }
    std::printf("fuzz_make_corpus: %zu candidate seeds in %s\n", out.count(), argv[3]);
    return 0;
}
