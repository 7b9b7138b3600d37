// The verbs of the `fins` CLI. Each returns the process exit code.
#pragma once

#include <string>
#include <system_error>
#include <vector>

#include <CLI/App.hpp>
#include <nlohmann/json.hpp>

#include "fins/client.hpp"

#include "cli/fins/value_format.hpp"

namespace fins::cli {

inline constexpr int exit_ok = 0;
inline constexpr int exit_usage = 2;
inline constexpr int exit_transport = 3;
inline constexpr int exit_end_code = 4;

struct GlobalOptions {
    std::string host = "127.0.0.1";
    std::uint16_t port = 9600;
    bool tcp = false;
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

// Prints results and errors in the chosen style and maps errors to exit codes.
class Output {
  public:
    explicit Output(bool json) : json_(json) {}
    [[nodiscard]] bool json() const { return json_; }
    // Usage errors: message on stderr (JSON: {"error": ...} on stdout), exit 2.
    int usage(const std::string& message);
    // Any failure from the client: end codes exit 4, everything else 3.
    int failure(std::error_code ec, const std::string& context);
    void print(const nlohmann::json& doc, const std::string& text);

  private:
    bool json_;
};

int run_read(const GlobalOptions& g, const ReadArgs& a, Format f, Output& out);
int run_write(const GlobalOptions& g, const WriteArgs& a, Format f, Output& out);
int run_fill(const GlobalOptions& g, const FillArgs& a, Output& out);
int run_transfer(const GlobalOptions& g, const TransferArgs& a, Output& out);
int run_read_multi(const GlobalOptions& g, const ReadMultiArgs& a, Output& out);
int run_raw(const GlobalOptions& g, const RawArgs& a, Output& out);

// Verbs of the other command groups register themselves; a verb's callback runs after
// the whole command line is parsed (global options may follow the verb) and stores the
// process exit code in `exit_code`. Each group lives in its own verbs_<group>.cpp.
void add_plc_data_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);  // 02 xx, 03 xx
void add_control_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);   // 04-07 xx
void add_diagnostic_verbs(CLI::App& app, const GlobalOptions& g,
                          int& exit_code);  // 06 01, 09, 0C, 21, 23
void add_file_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);  // 22 xx

// Connects with the global options, or prints why not and sets `exit_code`.
std::unique_ptr<Client> open_client(const GlobalOptions& g, Output& out, int& exit_code);

}  // namespace fins::cli
