// The JSON payload format (docs/bridge.md "Topics and payloads"):
//   {prefix}/{plc}/{group}            {"ts":1700000000000,"values":{"speed":12,"run":true,
//                                      "temp":{"error":"timeout"}}[,"full":true]}
//   {prefix}/{plc}/status             retained {"state":"online"|"offline"|"failing","ts":..,
//                                      "error":..} (failing: tag_failures.hpp)
//   {prefix}/$bridge/{instance}/status retained {"state":"online"|"offline","instance":..}
//   {prefix}/{plc}/write              in:  {"id":"..","tag":"temp","value":1.5[,"ts":ms]}
//   {prefix}/{plc}/write/response     out: {"id":..,"ok":..,"end_code":..,"value":..,"error":..}
// A tag that could not be read is {"error":"<text>","end_code":"1103"} (end_code only when
// the PLC answered one), never a value.
// A command's id is a string or an integer, and keeps its JSON type: 5 and "5" are two ids.
// WriteCommand::id and WriteResponse::id carry its JSON text ("\"w1\"", "5"), the key of
// the bridge's id memory; the response echoes the same JSON value.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "bridge/payload.hpp"

namespace fins::bridge {

// Longest string id (characters); a longer one is refused.
inline constexpr std::size_t max_id_chars = 128;

class JsonPayload final : public PayloadFormat {
  public:
    JsonPayload(std::string prefix, std::string instance);
    [[nodiscard]] std::vector<std::string> subscriptions() const override;
    [[nodiscard]] Message bridge_status(bool online) const override;
    void values(const GroupSample& sample, const Sink& out) override;
    void status(const PlcStatus& status, const Sink& out) override;
    void write_response(const Plc& plc, const WriteResponse& r, const Sink& out) override;
    std::optional<ParsedCommand> parse(std::string_view topic, std::string_view payload,
                                       bool retained) override;

  private:
    // A group's data topic and its tags' keys, `"name":` after `"name":`, rendered once.
    struct GroupText {
        std::string topic;
        std::string keys;
        std::vector<std::uint32_t> key_ends;  // tag i's key: [key_ends[i], key_ends[i + 1])
        std::vector<TagType> types;           // tag i's type
    };
    const GroupText& text_of(const GroupSample& s);

    std::string prefix_;
    std::string instance_;
    std::string buffer_;  // reused for every data message
    // By the group's address in the configuration, which outlives the format.
    std::unordered_map<const Group*, GroupText> groups_;
};

// The JSON text of an error: {"error":"...","end_code":"1103"}.
nlohmann::json error_json(std::error_code ec);

}  // namespace fins::bridge
