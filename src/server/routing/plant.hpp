// A plant in one process: several CPU Units, each with its Communications Units on FINS
// networks, joined by the Router (router.hpp). Each Communications Unit ("port") is one
// Server (FINS/UDP and FINS/TCP on its own bind address and port, its own 16 FINS/TCP
// connections, handshake and limits) whose Dispatcher is attached to the router.
//
// Start-up per CPU Unit: its Storage (data_dir/finsd.state, or memory that costs
// nothing until touched), the Plc, the operating mode, its file memory (data_dir/card,
// em, cassette, or a temporary root), the routing tables written into
// parameter area 8013 from the configuration (local network table from the ports,
// relay network table from `relays`), then one Server per port.
//
// Node addresses (W596 2-3, W420 5-2): with the automatic methods a port's node is the
// last octet of its bind address (127.0.1.5 is node 5); the IP-address-table and
// combined methods take the configured node. A frame for a node outside this process is
// sent as a datagram to the address the sending port's node-address table gives
// (node_address_table.hpp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <tl/expected.hpp>

#include "fins/error.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "plc/routing_tables.hpp"
#include "plc/storage/storage.hpp"
#include "server/instructions/instruction_udp.hpp"
#include "server/routing/node_address_table.hpp"
#include "server/sessions/server.hpp"
#include "server/sessions/tcp_limits.hpp"
#include "transport/asio.hpp"

namespace fins::server {

class Router;
class Server;

struct PlantPortConfig {
    std::uint8_t unit_number = 0;  // 00-0F
    std::uint8_t network = 1;      // 01-7F
    std::uint8_t node = 0;         // 0 = the last octet of `bind`
    std::string bind = "127.0.0.1";
    std::uint16_t port = 9600;  // FINS/UDP and FINS/TCP (0 = any free port, tests)
    bool udp = true;
    bool tcp = true;
    std::size_t max_connections = 16;  // W596 2-2
    AddressMethod method = AddressMethod::automatic_dynamic;
    bool dynamic_remote_ip = true;       // W596 2-3 "Dynamically change remote IP"
    std::vector<IpTableEntry> ip_table;  // table and combined methods
};

// A CPU Unit's file memory devices at start ([files] of a single node, [plc.files] of a
// plant's CPU Unit). Unset: the profile's.
struct FileMemoryOptions {
    std::optional<std::uint32_t> card_kbytes;  // memory card capacity in KB; 0 = no card
    std::optional<std::uint8_t> em_file_bank;  // the first EM bank of EM file memory
    std::optional<bool> cassette;              // a Memory Cassette mounted (22 20, CP1H)
};

// Sets up the file memory (22 xx) of `plc`: the devices of `options`, then, with a data
// directory, <data_dir>/card, em and cassette (else a temporary root removed at exit).
// A device directory that is a symlink is followed and said at warn level (its files
// live outside the data directory, which its backups miss); `who` starts each line
// ("" or "plc \"A\": "). The one set-up of finsd's single node and of each plant CPU Unit.
// Empty, or the line refusing it (a symlink to no usable directory, an attach error).
struct FileMemoryRefusal {
    boost::system::error_code error;
    std::string message;
};
std::optional<FileMemoryRefusal> set_up_file_memory(
    plc::Plc& plc, const FileMemoryOptions& options,
    const std::optional<std::filesystem::path>& data_dir, std::string_view who);

// A CPU Unit's PLC on its state file (plc::open_plc) or the heap: the one opening of
// finsd's single node and of each plant CPU Unit, so both say the same. Every line about
// the operator's data goes to stderr whatever the log level (stdout's first line stays
// "listening <port>"), each starting with `who` ("" or "plc \"A\": "): a file moved aside
// by --reset-state, a file not stopped cleanly. A refusal is returned (finsd exits 3 with
// it): the file, why, the profile a file of another one was written for, and the way out.
struct CpuStateRefusal {
    std::error_code error;
    std::string message;
};
tl::expected<std::unique_ptr<plc::Plc>, CpuStateRefusal> open_cpu_state(
    const plc::Profile& profile, const std::optional<std::filesystem::path>& data_dir,
    plc::StorageOptions options, bool reset_state, std::string_view who);

// The profile whose name a state file's header holds ("unknown": none known).
std::string state_file_profile(const std::filesystem::path& file);

struct PlantCpuConfig {
    std::string name;
    std::string profile = "cj2h";
    plc::OperatingMode mode = plc::OperatingMode::run;
    // none: nothing kept; else finsd.state and the file memory's card, em, cassette
    std::optional<std::filesystem::path> data_dir;
    FileMemoryOptions files;  // [plc.files]
    std::vector<PlantPortConfig> ports;
    std::vector<plc::RelayNetwork> relays;  // relay network table
    std::uint8_t gateway_count = 0x02;      // the 02/07 option of the routing tables
    // false: 8013 is left as the state file holds it (02 02 changes survive restarts).
    bool write_routing_tables = true;
    // What an acknowledged write survives ([storage] durability of a single node).
    plc::Durability durability = plc::Durability::process;
    // The units the CPU Unit reports (05 02), when more than its profile's: a Serial
    // Communications Unit or Board mounted for Serial Gateway ports. None: the profile's.
    std::optional<std::vector<plc::UnitInfo>> units;
    // Where remote nodes are for this CPU Unit's Send/Rcv/SendCmd ([[remote]]), on each
    // of its units.
    std::vector<RemoteNode> remotes;
};

struct PlantConfig {
    std::vector<PlantCpuConfig> cpus;
    TcpLimits tcp_limits;
    // A state file refused for its content is moved aside and started empty (finsd
    // --reset-state); without it the plant does not start.
    bool reset_state = false;
};

// The server options of one Ethernet unit (address, ports, transports, FINS/TCP limits):
// the one translation used for finsd's single node and for each unit of a plant. The
// caller adds what only it knows (router, remotes). `unit.node` is passed as is (0 =
// derived by the server, server.hpp).
ServerOptions options_for(const PlantPortConfig& unit, const TcpLimits& limits);

// The unit through which CPU Unit `cpu` sends a network instruction to `network` (W342
// 5-1-1 routing tables): the unit on that network, else the unit on the relay network
// of the relay entry for it, else the first unit (network 00, the local network).
std::size_t unit_toward(const PlantCpuConfig& cpu, std::uint8_t network) noexcept;

// Cross-field checks: names, unique unit numbers per CPU Unit (at most 16 ports),
// unique (network, node) in the plant, automatic methods with node = last octet, at
// most 20 relay entries whose relay network is a local network of that CPU Unit.
// Empty when the configuration is usable, else one line naming the CPU Unit.
std::string validate_plant(const PlantConfig& config);

// The descriptors a plant keeps open: a FINS/UDP socket and a FINS/TCP listener per
// unit (each unit has its own address and port, as each Ethernet Unit has), a FINS/TCP
// client connection per [[remote]] with tcp on each unit, and the state file, its
// directory and the file memory's root per CPU Unit with a data_dir (without one, the
// file memory's temporary root is made, and held, at the unit's first 22 xx command).
// Nothing else holds a descriptor per unit (the timers share the one reactor on the one
// I/O thread). FINS/TCP connections that clients open come on top (at most
// max_connections per unit). Plant::start refuses a plant that would leave fewer than
// descriptor_reserve under RLIMIT_NOFILE.
std::size_t plant_descriptors(const PlantConfig& config) noexcept;
inline constexpr std::size_t descriptor_reserve = 64;

class Plant {
  public:
    static Result<std::unique_ptr<Plant>> start(asio::io_context& io, const PlantConfig& config);
    ~Plant();
    Plant(const Plant&) = delete;
    Plant& operator=(const Plant&) = delete;

    [[nodiscard]] std::size_t cpu_count() const noexcept;
    plc::Plc& plc(std::size_t cpu) noexcept;
    // The index of the CPU Unit named `name`.
    [[nodiscard]] std::optional<std::size_t> find(std::string_view name) const noexcept;
    Router& router() noexcept;
    // The server of port `port` of CPU Unit `cpu` (in configuration order).
    Server& server(std::size_t cpu, std::size_t port) noexcept;

    // Closes every socket; flushes and closes the state files.
    void stop();

    struct Impl;

  private:
    explicit Plant(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace fins::server
