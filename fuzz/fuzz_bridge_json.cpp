// Fuzzes fins-bridge's JSON write commands (docs/bridge.md "Writes") through the Bridge
// itself: the JSON parse, the id memory and the refusal path, with a fixed small
// configuration whose PLC is not polled (no sockets: every write is refused). Every message
// on a {prefix}/{plc}/write topic must get exactly one response, a JSON object with "ok"
// false, an "id" that is a string or an integer, and an "error" text; any other topic none.
//
// Input: byte 0 picks the topic (bit 0-1: the configured PLC, an unknown one, an empty
// name, or a topic taken from the input up to the first '\n'; bit 2: retained); the rest
// (after that topic) is the payload. Several messages per input are separated by "\n--\n"
// so that repeated ids meet the id memory.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "bridge/bridge.hpp"
#include "bridge/json_payload.hpp"

namespace {

using namespace fins::bridge;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

// JsonPayload, with every write response kept.
class Recording final : public PayloadFormat {
  public:
    std::vector<Message> responses;
    [[nodiscard]] std::vector<std::string> subscriptions() const override {
        return json_.subscriptions();
    }
    [[nodiscard]] Message bridge_status(bool online) const override {
        return json_.bridge_status(online);
    }
    void values(const GroupSample& s, const Sink& out) override { json_.values(s, out); }
    void status(const PlcStatus& s, const Sink& out) override { json_.status(s, out); }
    void write_response(const Plc& plc, const WriteResponse& r, const Sink& out) override {
        json_.write_response(plc, r, [&](Message&& m) {
            responses.push_back(m);
            out(std::move(m));
        });
    }
    std::optional<ParsedCommand> parse(std::string_view topic, std::string_view payload,
                                       bool retained) override {
        return json_.parse(topic, payload, retained);
    }

  private:
    JsonPayload json_{"f", "fuzz"};
};

const BridgeConfig& config() {
    static const BridgeConfig c = [] {
        auto parsed = parse_config(
            "[mqtt]\ntopic_prefix = \"f\"\n[write]\nid_memory = 4\n"
            "[[plc]]\nname = \"p\"\nhost = \"127.0.0.1\"\nport = 9\n[[plc.group]]\nname = \"g\"\n"
            "tags = [{name=\"i\",address=\"D0\",type=\"int16\",writable=true,min=-5,max=5},\n"
            "        {name=\"f\",address=\"D2\",type=\"float\",writable=true},\n"
            "        {name=\"b\",address=\"D4.03\",type=\"bool\",writable=true},\n"
            "        {name=\"s\",address=\"D6\",type=\"string\",length=4,writable=true},\n"
            "        {name=\"r\",address=\"D10\",type=\"uint32\"}]\n",
            "fuzz.toml", "fuzz");
        check(parsed.has_value());
        return *parsed;
    }();
    return c;
}

bool is_write_topic(std::string_view t) {
    return t.size() >= 8 && t.starts_with("f/") && t.ends_with("/write");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const bool quiet = [] {
        spdlog::set_level(spdlog::level::off);
        return true;
    }();
    (void)quiet;
    if (size == 0) return 0;
    const std::uint8_t mode = data[0];
    std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
    std::string topic;
    switch (mode & 3) {
        case 0:
            topic = "f/p/write";
            break;
        case 1:
            topic = "f/nosuch/write";
            break;
        case 2:
            topic = "f//write";
            break;
        default: {
            const auto nl = rest.find('\n');
            topic = std::string(rest.substr(0, nl));
            rest = nl == std::string_view::npos ? std::string_view{} : rest.substr(nl + 1);
        }
    }
    const bool retained = (mode & 4) != 0;

    boost::asio::io_context io;
    auto format = std::make_unique<Recording>();
    auto& recorded = *format;
    Bridge bridge(io, config(), std::move(format), std::make_unique<SingleInstance>());
    std::size_t messages = 0;
    constexpr std::string_view separator = "\n--\n";
    while (messages < 64) {
        const auto at = rest.find(separator);
        bridge.incoming(topic, std::string(rest.substr(0, at)), retained);
        ++messages;
        io.restart();
        io.poll();
        if (at == std::string_view::npos) break;
        rest.remove_prefix(at + separator.size());
    }
    const bool answered = is_write_topic(topic);
    check(recorded.responses.size() == (answered ? messages : 0));
    for (const auto& m : recorded.responses) {
        check(m.topic == topic + "/response");
        check(m.qos == 1 && !m.retain);
        const auto j = nlohmann::json::parse(m.payload, nullptr, false);
        check(j.is_object());
        check(j.contains("ok") && j["ok"] == false);
        check(j.contains("id") && (j["id"].is_string() || j["id"].is_number_integer()));
        check(j.contains("error") && j["error"].is_string() &&
              !j["error"].get<std::string>().empty());
    }
    // Remembered: only for the configured PLC, at most id_memory ids.
    check(bridge.remembered_plcs() <= 1 && bridge.remembered_ids() <= 4);
    return 0;
}
