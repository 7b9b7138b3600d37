// finskit.VirtualPlc: finsd's Server and virtual CPU Unit in-process, on their own
// thread. The PLC is touched only on that thread (as in finsd): direct memory access
// and injected conditions are posted to it and waited for with the GIL released.
// A scenario (docs/scenarios.md) runs on that thread too, as in finsd; with
// time = "virtual" it moves only by advance().
#include <chrono>
#include <filesystem>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <spdlog/spdlog.h>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "errors.hpp"
#include "fins/address.hpp"
#include "finsd/config.hpp"
#include "finsd/config_scenario.hpp"
#include "finsd/scenario_setup.hpp"
#include "plc/injections.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"
#include "scenario/scenario.hpp"
#include "server/scenario/scenario_control.hpp"
#include "server/scenario/scenario_runner.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace py = pybind11;
using release = py::call_guard<py::gil_scoped_release>;

namespace finskit {

namespace {

fins::plc::Profile find(const std::string& name) {
    if (const auto* p = fins::plc::find_profile(name)) return *p;
    std::string known;
    for (const auto& p : fins::plc::profiles())
        known += (known.empty() ? "" : ", ") + p.name;
    throw BadArgument("unknown profile '" + name + "' (known: " + known + ")");
}

// Where a scenario comes from: a file, or TOML text holding a [scenario] table.
struct ScenarioSource {
    std::string value;
    bool is_text = false;
};

// VirtualPlc(scenario=...): a str with a line break is TOML text, any other str or an
// os.PathLike names a file. Runs with the GIL held (before the constructor releases it).
std::optional<ScenarioSource> scenario_source(const py::object& scenario) {
    if (scenario.is_none()) return std::nullopt;
    if (py::isinstance<py::str>(scenario)) {
        auto text = scenario.cast<std::string>();
        const bool is_text = text.find('\n') != std::string::npos;
        return ScenarioSource{std::move(text), is_text};
    }
    if (py::hasattr(scenario, "__fspath__"))
        return ScenarioSource{
            py::module_::import("os").attr("fspath")(scenario).cast<std::string>(), false};
    throw BadArgument("scenario must be a file path or TOML text holding a [scenario] table");
}

class VirtualPlc {
  public:
    VirtualPlc(const std::string& profile, std::string host, std::uint16_t port,
               const std::string& mode, std::optional<std::string> data_dir, std::uint8_t node,
               const std::string& log_level, const std::optional<ScenarioSource>& scenario)
        : host_(std::move(host)) {
        // finsd's log (spdlog, process-wide); "warn" keeps test output quiet.
        const auto level = spdlog::level::from_str(log_level);
        if (level == spdlog::level::off && log_level != "off")
            throw BadArgument("log_level must be trace, debug, info, warn, error or off");
        spdlog::set_level(level);
        const auto parsed_mode = fins::finsd::parse_mode(mode);
        if (!parsed_mode) throw BadArgument("mode must be program, monitor or run");
        auto model = find(profile);
        std::unique_ptr<fins::plc::Storage> storage;
        if (data_dir)
            storage = value_or_throw(fins::plc::Storage::open(*data_dir, model.name),
                                     "data directory " + *data_dir);
        profile_ = model.name;
        model_ = model.model;
        plc_ = std::make_unique<fins::plc::Plc>(model, std::move(storage));
        value_or_throw(plc_->storage().seal(), "state file");
        plc_->change_mode(*parsed_mode, std::chrono::system_clock::now());
        fins::server::ServerOptions options;
        options.bind_address = host_;
        options.port = port;
        options.node = node;
        server_ =
            value_or_throw(fins::server::Server::start(io_, *plc_, options), "listen on " + host_);
        port_ = server_->udp_port() != 0 ? server_->udp_port() : server_->tcp_port();
        if (scenario) start_scenario(*scenario);
        thread_ = std::thread([this] { io_.run(); });
    }
    ~VirtualPlc() { stop(); }
    VirtualPlc(const VirtualPlc&) = delete;
    VirtualPlc& operator=(const VirtualPlc&) = delete;

    void stop() {
        if (!thread_.joinable()) return;
        asio::post(io_, [this] {
            if (scenario_) scenario_->stop();
            server_->stop();
            work_.reset();
            io_.stop();
        });
        thread_.join();
        // Releases the state file (and its lock) so another VirtualPlc may open it.
        scenario_.reset();
        server_.reset();
        plc_->storage().flush();
        plc_.reset();
    }

    [[nodiscard]] const std::string& host() const { return host_; }
    [[nodiscard]] std::uint16_t port() const { return port_; }
    [[nodiscard]] const std::string& profile() const { return profile_; }
    [[nodiscard]] const std::string& model() const { return model_; }
    [[nodiscard]] bool running() const { return thread_.joinable(); }

    // Direct access: no FINS frame, no network-protection or mode checks; the area,
    // range and read-only rules of 01 01 / 01 02 still apply (1101, 1103, 1104, 2101).
    std::vector<std::uint16_t> read_words(const std::string& text, std::uint32_t count) {
        return on_plc([&] {
            const auto range = locate(text, count, fins::use_read, fins::plc::Intent::read);
            std::vector<std::uint8_t> bytes(range.byte_size());
            fins::ByteWriter w(bytes);
            plc_->memory().read(range, w, std::chrono::system_clock::now());
            std::vector<std::uint16_t> words;
            for (std::size_t i = 0; i + 1 < bytes.size(); i += 2)
                words.push_back(static_cast<std::uint16_t>((bytes[i] << 8) | bytes[i + 1]));
            return words;
        });
    }
    void write_words(const std::string& text, const std::vector<std::uint16_t>& words) {
        on_plc([&] {
            const auto count = static_cast<std::uint32_t>(words.size());
            const auto range = locate(text, count, fins::use_write, fins::plc::Intent::write);
            std::vector<std::uint8_t> bytes;
            for (auto w : words) {
                bytes.push_back(static_cast<std::uint8_t>(w >> 8));
                bytes.push_back(static_cast<std::uint8_t>(w & 0xFF));
            }
            if (const auto code = plc_->memory().write(range, bytes); code != fins::EndCode{})
                throw Failure(fins::make_error_code(code), "write " + text);
            return 0;
        });
    }
    void set_mode(const std::string& mode) {
        const auto parsed = fins::finsd::parse_mode(mode);
        if (!parsed) throw BadArgument("mode must be program, monitor or run");
        on_plc([&] {
            plc_->change_mode(*parsed, std::chrono::system_clock::now());
            return 0;
        });
    }
    // Conditions no FINS command can cause (plc/injections.hpp, finsd's [inject]).
    void inject(bool battery_error, const std::vector<std::pair<std::uint16_t, std::string>>& fal,
                std::optional<std::pair<std::uint16_t, std::string>> fals,
                const std::vector<std::pair<std::size_t, std::string>>& messages,
                const std::vector<std::uint16_t>& errors) {
        fins::plc::Injections in;
        in.battery_error = battery_error;
        for (const auto& [n, text] : fal)
            in.fal.push_back({n, text});
        if (fals) in.fals = fins::plc::FalInjection{fals->first, fals->second};
        for (const auto& [n, text] : messages) {
            if (n >= in.messages.size()) throw BadArgument("message numbers are 0-7");
            in.messages[n] = text;
        }
        in.errors = errors;
        if (auto bad = fins::plc::validate(in); !bad.empty()) throw BadArgument(bad);
        on_plc([&] {
            fins::plc::apply(in, *plc_, std::chrono::system_clock::now());
            return 0;
        });
    }

    // The scenario's control verbs (`finsd ctl scenario ...`).
    std::uint64_t advance(double seconds) {
        if (!(seconds > 0 && seconds <= fins::server::max_advance_seconds))
            throw BadArgument("seconds must be above 0 and at most a week (604800)");
        return on_scenario([&](fins::server::ScenarioRunner& s) { return s.advance(seconds); });
    }
    void trigger(const std::string& event) {
        on_scenario([&](fins::server::ScenarioRunner& s) {
            if (!s.trigger(event)) throw BadArgument("the scenario has no event named " + event);
            return 0;
        });
    }
    void pause() {
        on_scenario([](fins::server::ScenarioRunner& s) {
            s.pause();
            return 0;
        });
    }
    void resume() {
        on_scenario([](fins::server::ScenarioRunner& s) {
            s.resume();
            return 0;
        });
    }
    [[nodiscard]] bool has_scenario() const { return scenario_ != nullptr; }
    // Copied on the PLC's thread; turned into a dict with the GIL held.
    fins::server::ScenarioRunStatus scenario_status() {
        return on_scenario([](fins::server::ScenarioRunner& s) { return s.run_status(); });
    }

  private:
    void start_scenario(const ScenarioSource& source) {
        auto loaded = source.is_text ? fins::finsd::load_scenario_text(source.value, "<scenario>")
                                     : fins::finsd::load_scenario_file(source.value);
        if (!loaded) throw BadArgument(loaded.error());
        auto compiled = fins::finsd::compile_scenario(*loaded, *plc_);
        if (!compiled) throw BadArgument(compiled.error());
        // Started before the I/O thread runs: its first real-time tick is on that thread.
        scenario_ =
            fins::finsd::run_scenario(io_, std::optional(std::move(*loaded)), std::move(*compiled),
                                      *plc_, std::nullopt, scenario_worker_);
        server_->dispatcher().attach_faults(scenario_.get());
    }

    template <class F>
    auto on_scenario(F f) -> decltype(f(std::declval<fins::server::ScenarioRunner&>())) {
        if (!scenario_)
            throw BadArgument("this VirtualPlc runs no scenario (VirtualPlc(scenario=...))");
        return on_plc([&] { return f(*scenario_); });
    }

    fins::plc::ElementRange locate(const std::string& text, std::uint32_t count, fins::AreaUse use,
                                   fins::plc::Intent intent) {
        const auto a = value_or_throw(fins::parse_address(text), "address '" + text + "'");
        const auto start = value_or_throw(fins::to_memory_address(a, fins::Access::word), text);
        return value_or_throw(plc_->memory().locate(start, count, use, intent), text);
    }

    // Runs f on the PLC's thread and returns its result (or rethrows its exception).
    template <class F>
    auto on_plc(F f) -> decltype(f()) {
        if (!running())
            throw Failure(fins::make_error_code(fins::ClientError::not_connected),
                          "virtual PLC stopped");
        std::packaged_task<decltype(f())()> task(std::move(f));
        auto result = task.get_future();
        asio::post(io_, [&task] { task(); });
        return result.get();
    }

    std::string host_;
    std::string profile_;
    std::string model_;
    std::uint16_t port_ = 0;
    asio::io_context io_{1};
    asio::executor_work_guard<asio::io_context::executor_type> work_{io_.get_executor()};
    std::unique_ptr<fins::plc::Plc> plc_;
    std::unique_ptr<fins::server::Server> server_;
    std::unique_ptr<fins::server::ScenarioWorker> scenario_worker_;  // outlives scenario_
    std::unique_ptr<fins::server::ScenarioRunner> scenario_;
    std::thread thread_;
};

}  // namespace

void register_virtual_plc(py::module_& m) {
    py::class_<VirtualPlc>(m, "VirtualPlc",
                           "finsd's virtual CPU Unit and FINS/UDP+TCP server, in this process "
                           "on its own thread. Port 0 picks a free port (see .port).")
        .def(py::init([](const std::string& profile, std::string host, std::uint16_t port,
                         const std::string& mode, std::optional<std::string> data_dir,
                         std::uint8_t node, const std::string& log_level,
                         const py::object& scenario) {
                 const auto source = scenario_source(scenario);
                 py::gil_scoped_release unlocked;
                 return std::make_unique<VirtualPlc>(profile, std::move(host), port, mode,
                                                     std::move(data_dir), node, log_level, source);
             }),
             py::arg("profile") = "cj2h", py::arg("host") = "127.0.0.1", py::arg("port") = 0,
             py::arg("mode") = "run", py::arg("data_dir") = py::none(), py::arg("node") = 0,
             py::arg("log_level") = "warn", py::arg("scenario") = py::none())
        .def("__enter__", [](VirtualPlc& self) -> VirtualPlc& { return self; })
        .def(
            "__exit__", [](VirtualPlc& self, const py::args&) { self.stop(); }, release())
        .def("stop", &VirtualPlc::stop, release(), "Stops serving and flushes the data dir.")
        .def_property_readonly("host", &VirtualPlc::host)
        .def_property_readonly("port", &VirtualPlc::port)
        .def_property_readonly("profile", &VirtualPlc::profile)
        .def_property_readonly("model", &VirtualPlc::model)
        .def_property_readonly("running", &VirtualPlc::running)
        .def("read_words", &VirtualPlc::read_words, py::arg("address"), py::arg("count") = 1,
             release(), "Reads memory directly (no FINS frame).")
        .def("write_words", &VirtualPlc::write_words, py::arg("address"), py::arg("values"),
             release(), "Writes memory directly (no FINS frame).")
        .def("set_mode", &VirtualPlc::set_mode, py::arg("mode"), release(),
             "'program', 'monitor' or 'run'.")
        .def("inject", &VirtualPlc::inject, py::kw_only(), py::arg("battery_error") = false,
             py::arg("fal") = std::vector<std::pair<std::uint16_t, std::string>>{},
             py::arg("fals") = py::none(),
             py::arg("messages") = std::vector<std::pair<std::size_t, std::string>>{},
             py::arg("errors") = std::vector<std::uint16_t>{}, release(),
             "Raises errors and registers messages as finsd's [inject] section does.")
        .def_property_readonly("has_scenario", &VirtualPlc::has_scenario)
        .def("advance", &VirtualPlc::advance, py::arg("seconds"), release(),
             "Runs that many seconds of scenario time now; returns the ticks run.")
        .def("trigger", &VirtualPlc::trigger, py::arg("event"), release(),
             "Starts the scenario's event of that name now.")
        .def("pause", &VirtualPlc::pause, release(), "Stops the scenario's real time.")
        .def("resume", &VirtualPlc::resume, release(), "Lets the scenario's real time go on.")
        .def(
            "scenario_status",
            [](VirtualPlc& self) {
                fins::server::ScenarioRunStatus st;
                {
                    py::gil_scoped_release unlocked;
                    st = self.scenario_status();
                }
                py::list events;
                for (const auto& e : st.status.events) {
                    py::dict d;
                    d["name"] = e.name;
                    d["fault"] = e.fault;
                    d["active"] = e.active;
                    events.append(d);
                }
                py::dict d;
                d["time_s"] = st.status.time_s;
                d["ticks"] = st.status.ticks;
                d["writes"] = st.status.writes;
                d["tags"] = st.status.tags;
                d["paused"] = st.paused;
                d["virtual_time"] = st.virtual_time;
                d["seed"] = st.seed;
                d["events"] = events;
                return d;
            },
            "The scenario's time, ticks, writes and events (as finsd ctl scenario status).");
}

}  // namespace finskit
