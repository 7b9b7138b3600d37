// The verbs of the `fins` CLI. Each returns the process exit code.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <CLI/App.hpp>
#include <nlohmann/json.hpp>

#include "fins/client.hpp"

#include "typed/value_format.hpp"

namespace fins::cli {

using typed::Format;
using typed::format_name;
using typed::parse_bit;
using typed::parse_format;
using typed::parse_words;
using typed::ParseError;
using typed::print_words;
using typed::Printed;
using typed::words_per_value;

inline constexpr int exit_ok = 0;
inline constexpr int exit_usage = 2;
inline constexpr int exit_transport = 3;
inline constexpr int exit_end_code = 4;

struct GlobalOptions {
    std::string host = "127.0.0.1";
    std::uint16_t port = 9600;
    bool tcp = false;
    std::string serial;  // --serial DEVICE[,baud=...]: FINS over Host Link
    unsigned unit = 0;   // --unit: Host Link unit number 0-31
    double timeout_seconds = 2.0;
    unsigned retries = 0;
    std::string dest;
    std::string source;
    bool json = false;
};

struct ReadArgs {
    std::string address;
    unsigned count = 1;
};
struct WriteArgs {
    std::string address;
    std::vector<std::string> values;
};
struct FillArgs {
    std::string address;
    unsigned count = 0;
    std::string value;
};
struct TransferArgs {
    std::string from;
    std::string to;
    unsigned count = 0;
};
struct ReadMultiArgs {
    std::vector<std::string> addresses;
};
struct RawArgs {
    std::string command;
    std::vector<std::string> parameters;
    bool no_response = false;
};

enum class ErrorKind { usage, end_code, transport };

// How many `unit`-byte elements one request or answer carries: the manual's `max`, or
// fewer when the link's frame (client.max_parameters() / max_response_data(): Host Link
// 540 / 538 bytes) holds less after `fixed` bytes.
inline std::size_t fit(std::size_t max, std::size_t link_bytes, std::size_t fixed,
                       std::size_t unit) {
    const std::size_t room = link_bytes > fixed ? (link_bytes - fixed) / unit : 0;
    return max < room ? max : room;
}

// "1 word", "3 words"; "1 entry"/"2 entries" with the plural given.
std::string plural(std::size_t n, std::string_view one);
std::string plural(std::size_t n, std::string_view one, std::string_view many);
// NET.NODE.UNIT as --dest takes it: network and node decimal, the unit decimal below 10
// and hex from 10 on (E1, FE; 0x10 when the hex has no letter).
std::string node_text(const NodeAddress& a);
// "bad address 'XX5': why"; an unknown area lists the areas there are.
std::string bad_address(const std::string& text, std::error_code ec);
// "host:port" ("[::1]:9600" for IPv6).
std::string endpoint(const GlobalOptions& g);

// Prints results and errors in the chosen style and maps errors to exit codes.
class Output {
  public:
    explicit Output(bool json) : json_(json) {}
    [[nodiscard]] bool json() const { return json_; }
    // Usage errors: "fins: MESSAGE" on stderr (JSON: {"error": {"kind": "usage", ...}} on
    // stdout too), exit 2.
    int usage(const std::string& message);
    // A failure from the client: end codes exit 4; address and argument errors found
    // before sending exit 2; everything else (timeout, connection, malformed answer) 3.
    // A 0201 answer asks the PLC which node it is and says what --dest to use.
    int failure(std::error_code ec, const std::string& context);
    // The text, or the JSON document; with note_flags() called, the document gets
    // "fatal_cpu_error" and "non_fatal_cpu_error" and a set flag is noted on stderr.
    void print(const nlohmann::json& doc, const std::string& text);
    // Records the CPU error flags (bits 7 and 6, W342 5-1-3) of an answer.
    void note_flags(ResponseCode code);
    // A relay error (end code bit 15, docs/networks.md "Seeing relay errors in the CLI"): failure()
    // names the relay node that answered, in the text and in the JSON "relay_error".
    void note_relay(const std::optional<RelayErrorSource>& relay) { relay_ = relay; }
    // The connection settings failures are explained against (set by open_client).
    void set_target(const GlobalOptions& g) { target_ = &g; }
    // What an end code means in this verb's own terms (the Loop Control Board's 1101 is
    // "unregistered block", not W342's memory area): failure() says `text` instead of
    // the W342 wording when it reports `code`.
    void explain(EndCode code, std::string text) { explained_ = {code, std::move(text)}; }
    // The source node the client sends as (set by open_client): a 2102 names it.
    void set_local_node(NodeAddress node) { local_ = node; }

  private:
    bool json_;
    const GlobalOptions* target_ = nullptr;
    bool flags_tracked_ = false;
    std::optional<RelayErrorSource> relay_;
    std::optional<NodeAddress> local_;
    std::optional<std::pair<EndCode, std::string>> explained_;
    bool fatal_ = false;
    bool non_fatal_ = false;
};

// "what: done/total unit (n%)" on stderr, redrawn in place, only when stderr is a
// terminal; the line is erased when the Progress goes away.
class Progress {
  public:
    Progress(std::string what, std::size_t total, std::string unit);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;
    void update(std::size_t done);

  private:
    std::string what_;
    std::string unit_;
    std::size_t total_;
    bool active_;
    bool shown_ = false;
};

// What answered a probe: its FINS address (the answer's source) and model (05 01).
struct FoundNode {
    NodeAddress address;
    NodeAddress local;  // the source node the request went out with
    std::string model;
};
// Asks the PLC at g.host:g.port who it is: over UDP one 05 01 to node 00 ("the local
// node", which the PLC answers with its own address), over TCP the node the FINS/TCP
// handshake reports. --dest is not used. On failure, why (connection refused, timeout).
Result<FoundNode> discover_node(const GlobalOptions& g);
// The DIP switch byte of 05 01 (pin k is bit k-1) of the PLC the options address;
// nothing when it cannot be read.
std::optional<std::uint8_t> read_dip_switch(const GlobalOptions& g);
// The node holding the access right of the PLC the options address, asked with 0C 01
// ACCESS RIGHT ACQUIRE: its 3001 refusal carries the holder (W342 5-3-24). Nothing when
// it cannot be asked or nobody holds it; should the 0C 01 find the right free, it is
// released again at once (0C 03).
std::optional<NodeAddress> access_right_holder(const GlobalOptions& g);
// What helps against a 3001: who holds the right, how to take it over or give it back.
std::string access_right_hint(const NodeAddress& holder);
// NET.NODE.UNIT: each part decimal, or hex with 0x or with a letter A-F (E1 = 225).
// NET.NODE is unit 0 (the CPU Unit), as the protection node lists write it.
std::optional<NodeAddress> parse_node_address(const std::string& s);

// After a failed parse: when the verb (or a group's sub-verb, `fins files ...`) is missing
// or unknown, what to say instead of CLI11's "A subcommand is required": the nearest
// verbs by edit distance, or the group's verbs. Nothing for every other parse error.
std::optional<std::string> explain_missing_verb(CLI::App& app);

// FINS_HOST and FINS_PORT as the defaults of --host and --port (a flag on the command
// line overrides its variable). A bad value: the usage message to print (exit 2).
std::optional<std::string> apply_environment(GlobalOptions& g, int argc, char** argv);
// The usage message for a --dest or --source that is not NET.NODE[.UNIT]; nothing when
// both are fine (or not given).
std::optional<std::string> check_node_options(const GlobalOptions& g);
// Registers the global options on `app` and describes them in every verb's --help.
void add_global_options(CLI::App& app, GlobalOptions& g);
void describe_global_options(CLI::App& app);

int run_read(const GlobalOptions& g, const ReadArgs& a, Format f, Output& out);
int run_write(const GlobalOptions& g, const WriteArgs& a, Format f, Output& out);
int run_fill(const GlobalOptions& g, const FillArgs& a, Output& out);
int run_transfer(const GlobalOptions& g, const TransferArgs& a, Output& out);
int run_read_multi(const GlobalOptions& g, const ReadMultiArgs& a, Output& out);
int run_raw(const GlobalOptions& g, const RawArgs& a, Output& out);
int run_probe(const GlobalOptions& g, Output& out);

// Verbs of the other command groups register themselves; a verb's callback runs after
// the whole command line is parsed (global options may follow the verb) and stores the
// process exit code in `exit_code`. Each group lives in its own verbs_<group>.cpp.
void add_plc_data_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);  // 02 xx, 03 xx
void add_control_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);   // 04-07 xx
void add_diagnostic_verbs(CLI::App& app, const GlobalOptions& g,
                          int& exit_code);  // 06 01, 09, 0C, 21, 23
void add_file_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);  // 22 xx

// Sends `command` and decodes the answer like Client::send, noting the answer's CPU error
// flags on `out` (Client::send drops them: 0040 is a normal completion).
template <class C>
Result<typename C::Response> send_noting_flags(Client& client, const C& command, Output& out) {
    std::array<std::uint8_t, max_parameter_size> buffer{};
    ByteWriter w(buffer);
    command.encode(w);
    if (w.overflowed()) return Unexpected(make_error_code(ClientError::request_too_long));
    auto r = client.send_raw(C::code, w.written());
    if (!r) return Unexpected(r.error());
    out.note_flags(r->code);
    if (r->code.relay_error()) out.note_relay(r->relay);
    if (!r->code.ok()) return Unexpected(make_error_code(r->code.end_code()));
    return command.decode_response(r->data);
}

// Connects with the global options, or prints why not and sets `exit_code`.
std::unique_ptr<Client> open_client(const GlobalOptions& g, Output& out, int& exit_code);

// Connects and sends `command`: its response, or nullopt with `rc` set and the failure
// printed (the verb's name, C::name, says what failed).
template <class C>
std::optional<typename C::Response> send(const GlobalOptions& g, Output& out, int& rc,
                                         const C& command) {
    auto client = open_client(g, out, rc);
    if (!client) return std::nullopt;
    auto r = client->send(command);
    if (!r) {
        rc = out.failure(r.error(), std::string(C::name));
        return std::nullopt;
    }
    rc = exit_ok;
    return *r;
}

}  // namespace fins::cli
