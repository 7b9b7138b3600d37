// Plant: start-up of several CPU Units and their ports, glued by the Router (plant.hpp).
#include "server/routing/plant.hpp"

#ifndef _WIN32
#include <sys/resource.h>
#endif

#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"
#include "server/routing/router.hpp"
#include "server/sessions/server.hpp"

namespace fins::server {

namespace {

bool automatic(AddressMethod m) noexcept {
    return m == AddressMethod::automatic_dynamic || m == AddressMethod::automatic_static;
}

std::uint8_t port_node(const PlantPortConfig& p) noexcept {
    if (p.node != 0) return p.node;
    const auto ip = parse_ipv4(p.bind);
    return ip ? node_of(*ip) : 0;
}

}  // namespace

ServerOptions options_for(const PlantPortConfig& unit, const TcpLimits& limits) {
    ServerOptions options;
    options.bind_address = unit.bind;
    options.port = unit.port;
    options.udp = unit.udp;
    options.tcp = unit.tcp;
    options.node = unit.node;
    options.network = unit.network;
    options.max_tcp_connections = unit.max_connections;
    options.tcp_limits = limits;
    return options;
}

std::optional<FileMemoryRefusal> set_up_file_memory(
    plc::Plc& plc, const FileMemoryOptions& options,
    const std::optional<std::filesystem::path>& data_dir, std::string_view who) {
    auto& files = plc.files();
    if (options.card_kbytes) {
        if (*options.card_kbytes == 0)
            files.remove_card();
        else
            files.insert_card(*options.card_kbytes);
    }
    if (options.em_file_bank) files.set_em_file_bank(*options.em_file_bank);
    if (options.cassette) files.mount_cassette(*options.cassette);
    if (!data_dir) return std::nullopt;
    const auto r = files.attach(*data_dir);
    // A device directory that is a symlink is followed (plc/file_memory/file_memory.hpp): say so.
    for (const auto& link : files.device_links()) {
        const auto path = (*data_dir / link.device).string();
        if (link.error)
            return FileMemoryRefusal{
                link.error, fmt::format("{}file memory: {} is a symlink to {}, not a usable "
                                        "directory: {}",
                                        who, path, link.target.string(), link.error.message())};
        // A warning: files then live outside the data directory, which backups of that
        // directory miss; the operator should see it at any log level but error.
        spdlog::warn("finsd: {}file memory: {} is a symlink to {}: followed (nothing below it is)",
                     who, path, link.target.string());
    }
    if (!r)
        return FileMemoryRefusal{r.error(), fmt::format("{}file memory in {}: {}", who,
                                                        data_dir->string(), r.error().message())};
    return std::nullopt;
}

std::size_t unit_toward(const PlantCpuConfig& cpu, std::uint8_t network) noexcept {
    const auto on = [&](std::uint8_t n) -> std::optional<std::size_t> {
        for (std::size_t i = 0; i < cpu.ports.size(); ++i)
            if (cpu.ports[i].network == n) return i;
        return std::nullopt;
    };
    if (const auto local = on(network)) return *local;
    for (const auto& r : cpu.relays)
        if (r.network == network)
            if (const auto via = on(r.relay_network)) return *via;
    return 0;
}

std::string validate_plant(const PlantConfig& config) {
    if (config.cpus.empty()) return "plc: no CPU Unit";
    std::set<std::string> names;
    std::set<std::pair<int, int>> nodes;
    std::map<std::filesystem::path, std::string> data_dirs;
    for (const auto& cpu : config.cpus) {
        const std::string who = fmt::format("plc \"{}\"", cpu.name);
        if (cpu.name.empty()) return "plc: a CPU Unit without a name";
        if (!names.insert(cpu.name).second) return who + ": the name is used twice";
        // Each state file is locked by its one CPU Unit (plc/storage/storage.hpp).
        if (cpu.data_dir) {
            const auto [at, inserted] =
                data_dirs.emplace(cpu.data_dir->lexically_normal(), cpu.name);
            if (!inserted)
                return fmt::format("{}: data_dir {} is plc \"{}\"'s too", who,
                                   cpu.data_dir->string(), at->second);
        }
        if (plc::find_profile(cpu.profile) == nullptr)
            return fmt::format("{}: unknown profile '{}'", who, cpu.profile);
        if (cpu.ports.empty()) return who + ": no [[plc.ethernet]] unit";
        if (cpu.ports.size() > plc::max_local_networks)
            return fmt::format("{}: {} units, at most {} (the local network table's size)", who,
                               cpu.ports.size(), plc::max_local_networks);
        std::set<int> units, networks;
        for (const auto& p : cpu.ports) {
            const auto ip = parse_ipv4(p.bind);
            if (!ip)
                return fmt::format("{}: unit {}: bind '{}' is not an IPv4 address", who,
                                   p.unit_number, p.bind);
            if (!p.udp && !p.tcp)
                return fmt::format("{}: unit {}: udp and tcp are both off", who, p.unit_number);
            if (!units.insert(p.unit_number).second)
                return fmt::format("{}: unit number {} is used twice", who, p.unit_number);
            if (!networks.insert(p.network).second)
                return fmt::format("{}: two units on network {}", who, p.network);
            const auto node = port_node(p);
            if (node == 0 || node == 255)
                return fmt::format("{}: unit {}: no node address 1-254 (bind {})", who,
                                   p.unit_number, p.bind);
            // W420 5-2: with automatic generation the node must be the IP host number.
            if (automatic(p.method) && node != node_of(*ip))
                return fmt::format(
                    "{}: unit {}: node {} differs from the last octet of {} (automatic "
                    "generation: node = host number; use address_method = \"table\" or "
                    "\"combined\")",
                    who, p.unit_number, node, p.bind);
            if (!nodes.insert({p.network, node}).second)
                return fmt::format("{}: unit {}: node {}.{} exists twice in the plant", who,
                                   p.unit_number, p.network, node);
        }
        if (cpu.relays.size() > plc::max_relay_networks)
            return fmt::format("{}: {} relay entries, at most {}", who, cpu.relays.size(),
                               plc::max_relay_networks);
        std::set<int> destinations;
        for (const auto& r : cpu.relays) {
            if (networks.count(r.relay_network) == 0)
                return fmt::format(
                    "{}: relay to network {}: relay network {} is not a network "
                    "of this CPU Unit's units",
                    who, r.network, r.relay_network);
            if (networks.count(r.network) != 0 || !destinations.insert(r.network).second)
                return fmt::format("{}: relay to network {}: a local network or listed twice", who,
                                   r.network);
        }
    }
    return {};
}

struct Plant::Impl {
    struct Cpu {
        std::string name;
        std::unique_ptr<plc::Plc> plc;
        std::vector<std::unique_ptr<Server>> servers;
    };
    Router router;
    std::vector<Cpu> cpus;
    std::vector<Server*> by_port;  // the router's port index -> its server
};

namespace {}  // namespace

std::size_t plant_descriptors(const PlantConfig& config) noexcept {
    std::size_t n = 0;
    for (const auto& cpu : config.cpus) {
        for (const auto& p : cpu.ports)
            n += (p.udp ? 1u : 0u) + (p.tcp ? 1u : 0u);
        for (const auto& r : cpu.remotes)
            n += r.tcp ? cpu.ports.size() : 0u;
        if (cpu.data_dir) n += 3;  // the locked directory, its state file, the file memory
    }
    return n;
}

namespace {

// The descriptors this process has open now.
#ifndef _WIN32
std::size_t open_descriptors() {
    std::error_code ec;
    std::size_t n = 0;
    for (std::filesystem::directory_iterator it("/proc/self/fd", ec), end; !ec && it != end;
         it.increment(ec))
        ++n;
    return n;
}
#endif

}  // namespace

Result<std::unique_ptr<Plant>> Plant::start(asio::io_context& io, const PlantConfig& config) {
    // Refuse up front what would fail at the 9,000th unit: every unit's sockets, with
    // room left for FINS/TCP connections and the process's own files. (Windows has no
    // such per-process limit on sockets and files: nothing to check there.)
#ifndef _WIN32
    if (rlimit limit{};
        ::getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
        const std::size_t sockets = plant_descriptors(config);
        const std::size_t open = open_descriptors();
        const std::size_t needed = sockets + open + descriptor_reserve;
        if (needed > limit.rlim_cur) {
            spdlog::error(
                "finsd: the plant needs {} descriptors ({} for its units' sockets and state "
                "files, {} open, {} kept for connections and files) but the limit is {} "
                "(ulimit -n): raise it, or set tcp = false on units no FINS/TCP client uses",
                needed, sockets, open, descriptor_reserve, limit.rlim_cur);
            return Unexpected(std::make_error_code(std::errc::too_many_files_open));
        }
    }
#endif
    auto impl = std::make_unique<Impl>();
    impl->cpus.reserve(config.cpus.size());
    for (const auto& c : config.cpus) {
        plc::Profile profile = *plc::find_profile(c.profile);
        if (c.units) profile.units = *c.units;
        auto plc = open_cpu_state(profile, c.data_dir, {c.durability}, config.reset_state,
                                  fmt::format("plc \"{}\": ", c.name));
        if (!plc) {
            // On stderr whatever the log level, as a single node's refusal.
            std::fprintf(stderr, "finsd: %s\n", plc.error().message.c_str());
            return Unexpected(plc.error().error);
        }
        (*plc)->change_mode(c.mode, std::chrono::system_clock::now());
        if (const auto refused = set_up_file_memory(**plc, c.files, c.data_dir,
                                                    fmt::format("plc \"{}\": ", c.name))) {
            spdlog::error("finsd: {}", refused->message);
            return Unexpected(refused->error);
        }

        plc::RoutingTables tables;
        tables.gateway_count = c.gateway_count;
        for (const auto& p : c.ports)
            tables.local[tables.local_count++] = plc::LocalNetwork{p.network, p.unit_number};
        for (const auto& r : c.relays)
            tables.relay[tables.relay_count++] = r;
        if (c.write_routing_tables)
            plc::encode_routing_tables(tables, (*plc)->parameters().words(plc::routing_table_area));

        const auto cpu = impl->router.add_cpu(**plc, profile.nx_fixed_values);
        impl->cpus.push_back(Impl::Cpu{c.name, std::move(*plc), {}});
        auto& owner = impl->cpus.back();
        for (const auto& p : c.ports) {
            const NodeAddress self{p.network, port_node(p), cpu_unit};
            const auto index = impl->router.add_port(cpu, p.unit_number, self);
            PlantPortConfig unit = p;
            unit.node = self.node;
            auto options = options_for(unit, config.tcp_limits);
            options.router = &impl->router;
            options.router_port = index;
            options.remotes = c.remotes;
            auto server = Server::start(io, *owner.plc, options);
            if (!server) {
                spdlog::error("finsd: plc \"{}\" unit {}: cannot listen on {} port {}: {}", c.name,
                              p.unit_number, p.bind, p.port, server.error().message());
                return Unexpected(server.error());
            }
            impl->router.set_dispatcher(index, (*server)->dispatcher());
            const Ipv4Endpoint own{*parse_ipv4(p.bind), (*server)->udp_port()};
            impl->router.set_addresses(
                index, NodeAddressTable(p.method, p.dynamic_remote_ip, own, p.ip_table));
            impl->by_port.push_back(server->get());
            owner.servers.push_back(std::move(*server));
        }
    }
    auto* raw = impl.get();
    impl->router.set_wire([raw](std::size_t port, std::uint8_t node, Bytes frame) {
        // A FINS/TCP client holding that node gets it on its connection (W421 7-4 pairs
        // each node with one connection); anything else goes by FINS/UDP.
        if (raw->by_port[port]->send_to_tcp_node(node, frame)) return true;
        const auto to = raw->router.port(port).addresses.lookup(node);
        if (!to) return false;
        return raw->by_port[port]->send_datagram(frame, to->ip, to->port);
    });
    return std::unique_ptr<Plant>(new Plant(std::move(impl)));
}

Plant::Plant(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Plant::~Plant() {
    stop();
}

std::size_t Plant::cpu_count() const noexcept {
    return impl_->cpus.size();
}

plc::Plc& Plant::plc(std::size_t cpu) noexcept {
    return *impl_->cpus[cpu].plc;
}

std::optional<std::size_t> Plant::find(std::string_view name) const noexcept {
    for (std::size_t i = 0; i < impl_->cpus.size(); ++i)
        if (impl_->cpus[i].name == name) return i;
    return std::nullopt;
}

Router& Plant::router() noexcept {
    return impl_->router;
}

Server& Plant::server(std::size_t cpu, std::size_t port) noexcept {
    return *impl_->cpus[cpu].servers[port];
}

void Plant::stop() {
    for (auto& cpu : impl_->cpus) {
        for (auto& s : cpu.servers)
            s->stop();
        cpu.plc->storage().flush();
    }
}

}  // namespace fins::server
