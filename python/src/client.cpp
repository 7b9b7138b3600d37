// finskit.Client: fins::Client for Python. Every call that waits on the network runs
// with the GIL released (py::call_guard), so other Python threads keep running.
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "errors.hpp"
#include "fins/client.hpp"
#include "fins/commands/clock.hpp"
#include "fins/commands/diagnostics.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/commands/operating_mode.hpp"

namespace py = pybind11;
using release = py::call_guard<py::gil_scoped_release>;

namespace finskit {

namespace {

fins::Address address(const std::string& text) {
    return value_or_throw(fins::parse_address(text), "address '" + text + "'");
}

class Client {
  public:
    Client(std::string host, std::uint16_t port, const std::string& protocol, double timeout,
           unsigned retries) {
        fins::ClientOptions o;
        o.host = std::move(host);
        o.port = port;
        if (protocol == "tcp")
            o.protocol = fins::ClientOptions::Protocol::tcp;
        else if (protocol != "udp")
            throw BadArgument("protocol must be 'udp' or 'tcp', not '" + protocol + "'");
        if (!(timeout > 0.0) || timeout > 3600.0)
            throw BadArgument("timeout must be in (0, 3600] seconds");
        o.timeout = std::chrono::milliseconds{static_cast<long>(std::ceil(timeout * 1000.0))};
        o.retries = retries;
        client_ = value_or_throw(fins::Client::connect(o), "connect to " + o.host);
    }

    fins::Client& c() {
        if (!client_)
            throw Failure(fins::make_error_code(fins::ClientError::not_connected), "client closed");
        return *client_;
    }
    void close() { client_.reset(); }

    std::vector<std::uint16_t> read_words(const std::string& a, std::size_t count) {
        return value_or_throw(c().read_words(address(a), count), "read " + a);
    }
    void write_words(const std::string& a, const std::vector<std::uint16_t>& values) {
        value_or_throw(c().write_words(address(a), values), "write " + a);
    }
    std::vector<bool> read_bits(const std::string& a, std::size_t count) {
        return value_or_throw(c().read_bits(address(a), count), "read " + a);
    }
    void write_bits(const std::string& a, const std::vector<bool>& bits) {
        value_or_throw(c().write_bits(address(a), bits), "write " + a);
    }
    void fill(const std::string& a, std::size_t count, std::uint16_t value) {
        value_or_throw(c().fill(address(a), count, value), "fill " + a);
    }
    void transfer(const std::string& from, const std::string& to, std::size_t count) {
        value_or_throw(c().transfer(address(from), address(to), count), "transfer " + from);
    }
    std::vector<std::uint32_t> read_multiple(const std::vector<std::string>& texts) {
        std::vector<fins::Address> list;
        for (const auto& t : texts)
            list.push_back(address(t));
        return value_or_throw(c().read_multiple(list), "read-multi");
    }

    // 1-word-or-more reads of many addresses with up to `in_flight` requests on the wire
    // at once (async_send; one service ID each), in order of `texts`.
    std::vector<std::vector<std::uint16_t>> read_many(const std::vector<std::string>& texts,
                                                      std::uint16_t count, std::size_t in_flight) {
        if (in_flight < 1 || in_flight > 256) throw BadArgument("in_flight must be 1-256");
        if (count < 1 || count > fins::max_read_words) throw BadArgument("count must be 1-999");
        std::vector<fins::MemoryAreaRead> requests;
        for (const auto& t : texts) {
            fins::MemoryAreaRead r;
            r.start = value_or_throw(fins::to_memory_address(address(t), fins::Access::word), t);
            r.count = count;
            requests.push_back(r);
        }
        std::vector<std::vector<std::uint16_t>> out(requests.size());
        std::optional<Failure> failure;
        std::size_t next = 0;
        auto& client = c();
        std::function<void()> issue = [&] {
            const std::size_t i = next++;
            client.async_send(requests[i], [&, i](fins::Result<fins::MemoryAreaReadResponse> r) {
                if (!r) {
                    if (!failure) failure.emplace(r.error(), "read " + texts[i]);
                } else {
                    auto& words = out[i];
                    for (std::size_t b = 0; b + 1 < r->data.size(); b += 2)
                        words.push_back(
                            static_cast<std::uint16_t>((r->data[b] << 8) | r->data[b + 1]));
                }
                if (next < requests.size() && !failure) issue();
            });
        };
        while (next < requests.size() && next < in_flight)
            issue();
        client.run();
        if (failure) throw *failure;
        return out;
    }

    float read_float(const std::string& a) {
        return value_or_throw(c().read_float(address(a)), "read " + a);
    }
    void write_float(const std::string& a, float v) {
        value_or_throw(c().write_float(address(a), v), "write " + a);
    }
    double read_double(const std::string& a) {
        return value_or_throw(c().read_double(address(a)), "read " + a);
    }
    void write_double(const std::string& a, double v) {
        value_or_throw(c().write_double(address(a), v), "write " + a);
    }
    std::int16_t read_int16(const std::string& a) {
        return value_or_throw(c().read_int16(address(a)), "read " + a);
    }
    void write_int16(const std::string& a, std::int16_t v) {
        value_or_throw(c().write_int16(address(a), v), "write " + a);
    }
    std::int32_t read_int32(const std::string& a) {
        return value_or_throw(c().read_int32(address(a)), "read " + a);
    }
    void write_int32(const std::string& a, std::int32_t v) {
        value_or_throw(c().write_int32(address(a), v), "write " + a);
    }
    std::uint32_t read_uint32(const std::string& a) {
        return value_or_throw(c().read_uint32(address(a)), "read " + a);
    }
    void write_uint32(const std::string& a, std::uint32_t v) {
        value_or_throw(c().write_uint32(address(a), v), "write " + a);
    }
    std::string read_string(const std::string& a, std::size_t words) {
        return value_or_throw(c().read_string(address(a), words), "read " + a);
    }
    void write_string(const std::string& a, const std::string& s, std::size_t words) {
        value_or_throw(c().write_string(address(a), s, words), "write " + a);
    }

    // Any command, like W596 SendCmd: the end code is returned, not raised.
    std::tuple<std::uint16_t, py::bytes> raw(std::uint16_t command, const std::string& parameters) {
        fins::Result<fins::RawResponse> r;
        {
            py::gil_scoped_release unlocked;
            const fins::CommandCode code{static_cast<std::uint8_t>(command >> 8),
                                         static_cast<std::uint8_t>(command & 0xFF)};
            const auto* p = reinterpret_cast<const std::uint8_t*>(parameters.data());
            r = c().send_raw(code, fins::Bytes{p, parameters.size()});
        }
        auto response = value_or_throw(std::move(r), "raw command");
        return {response.code.raw(), py::bytes(reinterpret_cast<const char*>(response.data.data()),
                                               response.data.size())};
    }

    void run(bool monitor) {
        fins::Run command;
        command.mode = monitor ? fins::RunMode::monitor : fins::RunMode::run;
        value_or_throw(c().send(command), "04 01 RUN");
    }
    void stop() { value_or_throw(c().send(fins::Stop{}), "04 02 STOP"); }
    fins::CpuUnitStatusReadResponse status() {
        return value_or_throw(c().send(fins::CpuUnitStatusRead{}), "06 01 CPU UNIT STATUS READ");
    }

    // 07 01 CLOCK READ: the PLC's local time as a naive datetime.datetime.
    py::object clock() {
        fins::ClockTime t;
        {
            py::gil_scoped_release unlocked;
            t = value_or_throw(c().send(fins::ClockRead{}), "07 01 CLOCK READ").time;
        }
        return py::module_::import("datetime")
            .attr("datetime")(fins::full_year(t.year), t.month, t.day, t.hour, t.minute, t.second);
    }
    // 07 02 CLOCK WRITE (years 1998-2097, W342 5-3-19), day of week from the date.
    void set_clock(const py::object& when) {
        const int year = when.attr("year").cast<int>();
        if (year < 1998 || year > 2097) throw BadArgument("the PLC clock holds years 1998-2097");
        fins::ClockWrite w;
        w.year = static_cast<std::uint8_t>(year % 100);
        w.month = when.attr("month").cast<std::uint8_t>();
        w.day = when.attr("day").cast<std::uint8_t>();
        w.hour = when.attr("hour").cast<std::uint8_t>();
        w.minute = when.attr("minute").cast<std::uint8_t>();
        w.second = when.attr("second").cast<std::uint8_t>();
        // Python: Monday 0 .. Sunday 6; FINS: Sunday 0 .. Saturday 6.
        w.day_of_week = static_cast<std::uint8_t>((when.attr("weekday")().cast<int>() + 1) % 7);
        py::gil_scoped_release unlocked;
        value_or_throw(c().send(w), "07 02 CLOCK WRITE");
    }

  private:
    std::unique_ptr<fins::Client> client_;
};

}  // namespace

void register_client(py::module_& m) {
    py::class_<fins::CpuUnitStatusReadResponse>(m, "CpuStatus",
                                                "06 01 CPU UNIT STATUS READ (W342 5-3-17)")
        .def_property_readonly("running", &fins::CpuUnitStatusReadResponse::running)
        .def_property_readonly("mode",
                               [](const fins::CpuUnitStatusReadResponse& s) {
                                   return s.mode == fins::mode_run       ? "run"
                                          : s.mode == fins::mode_monitor ? "monitor"
                                                                         : "program";
                               })
        .def_readonly("fatal_errors", &fins::CpuUnitStatusReadResponse::fatal_errors)
        .def_readonly("non_fatal_errors", &fins::CpuUnitStatusReadResponse::non_fatal_errors)
        .def_readonly("error_code", &fins::CpuUnitStatusReadResponse::error_code)
        .def_readonly("error_message", &fins::CpuUnitStatusReadResponse::error_message);

    py::class_<Client>(m, "Client",
                       "A FINS client over UDP or TCP (libfins fins::Client). Addresses are "
                       "strings as in the fins CLI: 'D100', 'CIO10.13', 'E3_200', 'T5'.")
        .def(py::init<std::string, std::uint16_t, const std::string&, double, unsigned>(),
             py::arg("host"), py::arg("port") = 9600, py::arg("protocol") = "udp",
             py::arg("timeout") = 2.0, py::arg("retries") = 0, release())
        .def("__enter__", [](Client& self) -> Client& { return self; })
        .def("__exit__", [](Client& self, const py::args&) { self.close(); })
        .def("close", &Client::close, "Closes the connection.")
        .def("read_words", &Client::read_words, py::arg("address"), py::arg("count") = 1, release(),
             "01 01: `count` words from `address` (split above 999).")
        .def("write_words", &Client::write_words, py::arg("address"), py::arg("values"), release(),
             "01 02: writes the words (split above 997).")
        .def("read_bits", &Client::read_bits, py::arg("address"), py::arg("count") = 1, release())
        .def("write_bits", &Client::write_bits, py::arg("address"), py::arg("bits"), release())
        .def("fill", &Client::fill, py::arg("address"), py::arg("count"), py::arg("value"),
             release(), "01 03 MEMORY AREA FILL.")
        .def("transfer", &Client::transfer, py::arg("source"), py::arg("destination"),
             py::arg("count"), release(), "01 05 MEMORY AREA TRANSFER.")
        .def("read_multiple", &Client::read_multiple, py::arg("addresses"), release(),
             "01 04: one value per address (1, 2 or 4 bytes, big-endian).")
        .def("read_many", &Client::read_many, py::arg("addresses"), py::arg("count") = 1,
             py::arg("in_flight") = 32, release(),
             "01 01 for each address, up to `in_flight` requests pipelined at once.")
        .def("read_float", &Client::read_float, py::arg("address"), release())
        .def("write_float", &Client::write_float, py::arg("address"), py::arg("value"), release())
        .def("read_double", &Client::read_double, py::arg("address"), release())
        .def("write_double", &Client::write_double, py::arg("address"), py::arg("value"), release())
        .def("read_int16", &Client::read_int16, py::arg("address"), release())
        .def("write_int16", &Client::write_int16, py::arg("address"), py::arg("value"), release())
        .def("read_int32", &Client::read_int32, py::arg("address"), release())
        .def("write_int32", &Client::write_int32, py::arg("address"), py::arg("value"), release())
        .def("read_uint32", &Client::read_uint32, py::arg("address"), release())
        .def("write_uint32", &Client::write_uint32, py::arg("address"), py::arg("value"), release())
        .def("read_string", &Client::read_string, py::arg("address"), py::arg("words"), release())
        .def("write_string", &Client::write_string, py::arg("address"), py::arg("text"),
             py::arg("words") = 0, release())
        .def("raw", &Client::raw, py::arg("command"), py::arg("parameters") = py::bytes(),
             "Sends command 0xMMSS with the parameter bytes; returns (end_code, data). "
             "The end code is returned, not raised.")
        .def("run", &Client::run, py::arg("monitor") = false, release(), "04 01 RUN.")
        .def("stop", &Client::stop, release(), "04 02 STOP (PROGRAM mode).")
        .def("status", &Client::status, release(), "06 01 CPU UNIT STATUS READ.")
        .def("clock", &Client::clock, "07 01 CLOCK READ: a naive datetime (PLC local time).")
        .def("set_clock", &Client::set_clock, py::arg("when"),
             "07 02 CLOCK WRITE from a datetime (seconds and day of week included).");
}

}  // namespace finskit
