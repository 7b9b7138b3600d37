// fins::Client: a FINS client over UDP or TCP (frames sections 2-3), modelled on the
// NX SendCmd instruction (W596 section 3, SendCmd p. 3-16): per-request timeout, 0-15
// retries of the same frame, an optional no-response mode, many requests in flight
// (an NX CPU runs at most 32 Send/Rcv/SendCmd at once; this client allows 256, one per
// service ID, and the PLC's own limits still apply).
//
// Threading, two ways to run (one engine: docs/client.md "One engine"):
// - Client::connect(): the Client owns one asio::io_context and runs it only inside its
//   own calls (send*, run, the helpers, connect). Completion callbacks of async_send*()
//   run inside send*()/run()/a helper; a callback may call async_send*() again, but must
//   not destroy the Client. A synchronous call (send, send_raw, send_no_response, the
//   helpers) made inside a callback fails at once with ClientError::called_from_callback,
//   and run() returns at once there.
// - Client::create(io, options): embedded in the caller's io_context, which the caller
//   runs; many clients (and servers) share it. Name resolution, connect and handshake
//   are asynchronous (async_open(), or the first request); every completion runs on
//   `io`. Only async_open(), async_send*() and the state calls are for this client: the
//   synchronous calls fail with ClientError::called_from_callback and run() is a no-op.
//   Destroying it drops the requests in flight without callbacks.
// Either way a Client is NOT thread-safe: use it from the thread that runs its io_context.
//
// Requests: up to 256 accepted at once; one more fails with
// ClientError::too_many_in_flight. Each attempt waits `timeout`; after `retries`
// retransmissions the request fails with ClientError::timeout. A retry resends the
// identical frame, same SID (W596 p. 3-16: "try to resend the message"), so an answer to
// any attempt completes the request and a late answer to an earlier one is a duplicate. A response
// is matched by service ID (SID), command code and addresses; stale or duplicate answers are
// dropped and counted in stats().
//
// No late answer completes the wrong request: a read answer carries no address, only
// the SID. A SID whose request was retransmitted, timed out or failed after it was sent
// is quarantined for `sid_quarantine` (default twice the timeout) before it is used
// again; other SIDs are reused least recently used first; once the network has shown
// that it duplicates answers (an answer to a SID that had all its answers), every SID
// released within `sid_quarantine` of that is quarantined too. When no SID is usable a
// request waits in a queue (its timeout runs) instead of reusing one early. This holds
// as long as no datagram outlives the quarantine in the network. The quarantine follows
// the network: an awaited late answer that comes in the second half of `sid_quarantine`
// after its SID's release raises it to twice that delay (at most 64 times
// `sid_quarantine`) until such answers stop (engine/sid_pool.hpp).
//
// Errors (all std::error_code): EndCode for a non-zero end code in send<C>() and the
// helpers (end-code flag bits 0x0040/0x0080 alone still count as success; send_raw()
// returns every end code to the caller instead), ClientError for local failures, TcpError
// for FINS/TCP envelope and handshake errors, and system errors from resolve/connect and
// from the network (UDP: ICMP port unreachable fails the requests waiting at that moment
// with asio::error::connection_refused, "nothing listening"; host or network unreachable
// only costs the attempt, which times out and is retried). An error_code cannot carry the
// endpoint: describe_error() / Client::describe() put it in front of the message
// ("127.0.0.1:9600: connection refused").
//
// Connection loss: every request in flight fails with ClientError::connection_closed
// (TcpError after a command-3 notification). Nothing is re-sent automatically, since the
// PLC may have executed it. The next request reconnects (TCP: with a fresh handshake,
// which may allocate a different client node) and is sent once the link is up. A peer
// that closed while the client was idle (finsd restarted) is noticed before the next
// request is sent, so that request goes out on the new connection.
//
// Address defaults (node 0 in ClientOptions means "derive", unless
// ClientOptions::destination_as_given: then the destination is sent as written):
//   destination: TCP -> the server node from the handshake; UDP -> the last octet of
//                the host's IPv4 address, on loopback too (127.0.0.2 -> node 2; ::1 -> 1;
//                the last byte for other IPv6), as W420 5-2's automatic generation does.
//   source:      TCP -> the node the server allocated (or the one requested);
//                UDP -> the last octet of the local address; if that equals the
//                destination node (both on 127.0.0.1), 254 instead, so the two ends differ.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fins/address.hpp"
#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "fins/serial.hpp"

namespace boost::asio {
class io_context;
}

namespace fins {

struct ClientOptions {
    std::string host = "127.0.0.1";
    std::uint16_t port = 9600;
    enum class Protocol { udp, tcp, serial } protocol = Protocol::udp;
    // Protocol::serial: FINS over Host Link (docs/serial.md "Host Link (serial)") on this device,
    // to the PLC with this Host Link unit number (0-31). Half duplex: one request on the
    // line at a time, the others wait (their timeout starts when they are sent). The
    // direct form is used while destination and source network and node are 0 (the
    // directly connected CPU Unit), else the network form. An answer with a Host Link end
    // code fails the request with a HostLinkEndCode, one with a bad FCS with
    // HostLinkError::bad_fcs (fins/host_link.hpp). host/port are not used.
    SerialSettings serial;
    std::uint8_t host_link_unit = 0;
    NodeAddress destination;  // node 0: derive (see above), unless destination_as_given
    // Sent as written, node 0 too (W342: DA1 00 is "the local PLC"), and answered only from
    // exactly that node (another node's answer: other_node(), a timeout). Off: 00 derives.
    bool destination_as_given = false;
    NodeAddress source;  // node 0: derive (see above); TCP: sent in the handshake
    // Per attempt; also bounds connecting and the TCP handshake. W596 p. 3-16: 0 means 2.0 s.
    std::chrono::milliseconds timeout{2000};
    unsigned retries = 0;  // W596 p. 3-16 Option.Retry: 0-15
    std::uint8_t gateway_count = default_gateway_count;
    // How long a suspect SID rests before reuse: the longest a late answer may take to
    // arrive after its request was given up. 0: twice `timeout`.
    std::chrono::milliseconds sid_quarantine{0};
};

// "host:port" of the options ("[::1]:9600" for an IPv6 literal); serial: "DEVICE unit N".
std::string endpoint_name(const ClientOptions& options);
// "<endpoint>: <message>", e.g. "127.0.0.1:9600: connection refused".
std::string describe_error(const ClientOptions& options, std::error_code ec);

// A response exactly as received (W596 SendCmd p. 3-16 RespDat): the end code is not
// interpreted.
struct RawResponse {
    Header header;
    CommandCode command;
    ResponseCode code;
    std::optional<RelayErrorSource> relay;  // when code.relay_error()
    std::vector<std::uint8_t> data;         // bytes after the end code (and relay word)
};

struct ClientStats {
    std::uint64_t sent = 0;               // request frames sent (first attempts)
    std::uint64_t retransmitted = 0;      // frames re-sent after a timeout
    std::uint64_t completed = 0;          // responses matched to a request
    std::uint64_t timed_out = 0;          // requests failed with ClientError::timeout
    std::uint64_t failed = 0;             // requests failed by connection loss or close
    std::uint64_t stale_discarded = 0;    // answers to no request in flight / wrong command
    std::uint64_t invalid_discarded = 0;  // undecodable frames, wrong addresses
    // Of those: answers with the SID and command of a request in flight from another
    // node than the one it was sent to (the peer is not the node it is addressed as).
    std::uint64_t other_node_answers = 0;
    std::uint64_t reconnects = 0;     // successful opens after the first
    std::uint64_t quarantined = 0;    // SIDs put into quarantine (see above)
    std::uint64_t waited_for_id = 0;  // requests that waited for a usable SID
    // Late answers that showed the network holding datagrams nearly `sid_quarantine`,
    // and made the quarantine longer (see above).
    std::uint64_t quarantine_raised = 0;
};

class Client {
  public:
    // Resolves, connects (TCP: handshake) and derives the node addresses. Fails with
    // ClientError::invalid_argument (retries > 15), a resolve/connect error, a TcpError
    // from the handshake, or ClientError::timeout.
    static Result<std::unique_ptr<Client>> connect(ClientOptions options);
    // A client on the caller's io_context (see Threading). Only checks the options
    // (ClientError::invalid_argument as connect()); nothing is opened yet.
    static Result<std::unique_ptr<Client>> create(boost::asio::io_context& io,
                                                  ClientOptions options);
    // Resolves (asynchronously), connects and, over TCP, does the handshake, unless open
    // already; `done` runs on the io_context with the outcome of that open ({} when the
    // link is up). Requests submitted meanwhile wait for the link.
    void async_open(std::function<void(std::error_code)> done);
    // Closes the connection; requests still in flight are dropped without callbacks.
    ~Client();
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    // ---- typed commands (any type with code, Response, encode, decode_response) ----
    template <class C>
    Result<typename C::Response> send(const C& command);
    // The command is encoded before async_send() returns; a copy is kept to decode the
    // response (it must not need the views it holds, e.g. MemoryAreaWrite::data).
    template <class C>
    void async_send(const C& command, std::function<void(Result<typename C::Response>)> done);
    template <class C>
    Result<void> send_no_response(const C& command);

    // ---- raw access, like SendCmd: parameters = the bytes after MRC SRC ----
    Result<RawResponse> send_raw(CommandCode code, Bytes parameters);
    void async_send_raw(CommandCode code, Bytes parameters,
                        std::function<void(Result<RawResponse>)> done);
    // As async_send_raw() without copying the answer: `done` sees views into the receive
    // buffer, valid only during the call (a hot path such as a poller decoding in place).
    void async_send_view(CommandCode code, Bytes parameters,
                         std::function<void(Result<ResponseView>)> done);
    // ICF bit 0 (frames 1.2): nothing is awaited; returns once the frame has been handed
    // to the kernel (or after `timeout` if it could not be). Reconnects first if needed.
    Result<void> send_no_response(CommandCode code, Bytes parameters);

    // Runs until no request is in flight (returns at once inside a completion callback).
    void run();

    // ---- I/O memory helpers (01 01 .. 01 05, W342 5-3-2 .. 5-3-6) ----
    // Reads above 999 words / writes above 997 words (W342 5-2-2 "Number of Elements",
    // Ethernet) are split into several requests kept in flight together and joined; if
    // any part fails the whole call fails with that part's error (writes may then be
    // partly done). Bits use the same limits per element.
    Result<std::vector<std::uint16_t>> read_words(const Address& start, std::size_t count);
    Result<void> write_words(const Address& start, std::span<const std::uint16_t> words);
    // Bit addresses (D100.03, CIO10.15) step bit by bit; T/C/TK flags step word by word.
    Result<std::vector<bool>> read_bits(const Address& start, std::size_t count);
    Result<void> write_bits(const Address& start, const std::vector<bool>& bits);
    Result<void> fill(const Address& start, std::size_t count, std::uint16_t value);
    Result<void> transfer(const Address& from, const Address& to, std::size_t count);
    // 01 04, up to 167 addresses per request (W342 5-3-5), more are split. Each value is
    // the element's 1, 2 or 4 bytes, big-endian.
    Result<std::vector<std::uint32_t>> read_multiple(std::span<const Address> addresses);

    // Typed values in Omron word order (fins/values.hpp: least significant word first).
    Result<std::int16_t> read_int16(const Address& a);
    Result<std::uint16_t> read_uint16(const Address& a);
    Result<std::int32_t> read_int32(const Address& a);
    Result<std::uint32_t> read_uint32(const Address& a);
    Result<float> read_float(const Address& a);
    Result<double> read_double(const Address& a);
    Result<void> write_int16(const Address& a, std::int16_t v);
    Result<void> write_uint16(const Address& a, std::uint16_t v);
    Result<void> write_int32(const Address& a, std::int32_t v);
    Result<void> write_uint32(const Address& a, std::uint32_t v);
    Result<void> write_float(const Address& a, float v);
    Result<void> write_double(const Address& a, double v);
    Result<std::uint16_t> read_bcd16(const Address& a);  // 0-9999, one word
    Result<std::uint32_t> read_bcd32(const Address& a);  // 0-99999999, two words
    Result<void> write_bcd16(const Address& a, std::uint16_t v);
    Result<void> write_bcd32(const Address& a, std::uint32_t v);
    // `word_count` words, two characters per word, first in the high byte; stops at the
    // first 00 byte. Each byte is the character of the same code point (Latin-1), in
    // UTF-8; a write refuses a character above U+00FF (fins/values.hpp).
    Result<std::string> read_string(const Address& a, std::size_t word_count);
    // Writes ceil(size/2) words, or exactly `word_count` (padded with 00) when non-zero.
    Result<void> write_string(const Address& a, std::string_view s, std::size_t word_count = 0);

    // ---- state ----
    [[nodiscard]] ClientStats stats() const noexcept;
    [[nodiscard]] std::size_t in_flight() const noexcept;
    [[nodiscard]] bool is_connected() const noexcept;
    [[nodiscard]] const ClientOptions& options() const noexcept;
    // The addresses put in request headers (after derivation).
    [[nodiscard]] NodeAddress destination() const noexcept;
    [[nodiscard]] NodeAddress source() const noexcept;
    // The node that answered a request sent to destination() instead, since the last
    // answer that matched: configure it as the destination (or fix the peer's node).
    [[nodiscard]] std::optional<NodeAddress> other_node() const noexcept;
    // The most parameter bytes (after MRC SRC) a request may carry and response data
    // bytes an answer may carry: 2,000 / 1,998 over Ethernet (2,012-byte frames), 540 /
    // 538 over Host Link (W342 3-5). The helpers split by them.
    [[nodiscard]] std::size_t max_parameters() const noexcept;
    [[nodiscard]] std::size_t max_response_data() const noexcept;
    // describe_error(options(), ec).
    [[nodiscard]] std::string describe(std::error_code ec) const;
    // Closes the connection; requests in flight fail with ClientError::canceled. The next
    // request reconnects.
    void close();

    struct Impl;

  private:
    using ViewCompletion = std::function<void(Result<ResponseView>)>;

    explicit Client(std::unique_ptr<Impl> impl);
    // Submits a request; failures (too many in flight, not connected ...) reach `done`
    // from the io_context, never from inside submit().
    void submit(CommandCode code, Bytes parameters, ViewCompletion done);
    void fail_later(ViewCompletion done, std::error_code ec);
    Result<void> submit_no_response(CommandCode code, Bytes parameters);
    // Runs the io_context until `done()` is true; every request ends by its deadline.
    void run_until(const std::function<bool()>& done);
    // True inside a completion callback (the io_context is running).
    [[nodiscard]] bool in_callback() const noexcept;

    std::unique_ptr<Impl> impl_;
};

// ---- template definitions ----

template <class C>
void Client::async_send(const C& command, std::function<void(Result<typename C::Response>)> done) {
    std::array<std::uint8_t, max_parameter_size> buffer{};
    ByteWriter w(buffer);
    command.encode(w);
    auto finish = [command, done = std::move(done)](Result<ResponseView> r) {
        if (!r) return done(Unexpected(r.error()));
        if (!r->code.ok()) return done(Unexpected(make_error_code(r->code.end_code())));
        done(command.decode_response(r->data));
    };
    if (w.overflowed())
        return fail_later(std::move(finish), make_error_code(ClientError::request_too_long));
    submit(C::code, w.written(), std::move(finish));
}

template <class C>
Result<typename C::Response> Client::send(const C& command) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    std::optional<Result<typename C::Response>> out;
    async_send(command, [&out](Result<typename C::Response> r) { out.emplace(std::move(r)); });
    run_until([&out] { return out.has_value(); });
    if (!out) return Unexpected(make_error_code(ClientError::canceled));
    return std::move(*out);
}

template <class C>
Result<void> Client::send_no_response(const C& command) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    std::array<std::uint8_t, max_parameter_size> buffer{};
    ByteWriter w(buffer);
    command.encode(w);
    if (w.overflowed()) return Unexpected(make_error_code(ClientError::request_too_long));
    return submit_no_response(C::code, w.written());
}

// ---- file memory helpers (22 xx, W342 5-3-32 .. 5-3-42): src/client/file_transfer.cpp ----
// Types from fins/commands/file_memory.hpp; the other 22 xx commands go through
// Client::send<C>() one to one. `directory`: "" (root) or "\DIR\SUB".
struct FileName;
struct DirectoryListing;
// Called after each chunk: bytes done so far and the file's size.
using FileProgress = std::function<void(std::uint64_t done, std::uint64_t total)>;
// Every entry of a directory, over as many 22 01 requests (20 entries each) as needed.
Result<DirectoryListing> list_directory(Client& client, std::uint16_t disk,
                                        const std::string& directory);
// A whole file of any size: 22 02 chunks of up to 1,988 bytes, `window` kept in flight.
Result<std::vector<std::uint8_t>> get_file(Client& client, std::uint16_t disk,
                                           const std::string& directory, const FileName& file,
                                           const FileProgress& progress = {},
                                           std::size_t window = 8);
// Writes a whole file: the first 22 03 creates it (0001 with `replace`, else 0000: 2107
// when it exists), the rest write 0003 at their explicit positions, `window` in flight,
// and a final 22 02 checks the file's size. With ClientOptions::retries it completes
// through lost, duplicated and reordered datagrams: a chunk that overtook a lost one
// (refused 1103) is sent again after it, a repeated chunk rewrites the same bytes, and a
// file found shorter than acknowledged is resumed from its size. The file on the PLC is
// always a prefix of `data`; when the call fails, its size says how much arrived.
Result<void> put_file(Client& client, std::uint16_t disk, const std::string& directory,
                      const FileName& file, std::span<const std::uint8_t> data, bool replace,
                      const FileProgress& progress = {}, std::size_t window = 8);

}  // namespace fins
