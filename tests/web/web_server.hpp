// A finsd HTTP server on its own io_context thread for the tests, with helpers that run
// code on that thread (the PLC is touched only there) and a Beast client.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "server/metrics/metrics.hpp"
#include "web/http_server.hpp"

namespace fins::test {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;

class WebServer {
  public:
    // `fault`: WebContext::fault (the failure boundary's test hook).
    explicit WebServer(web::WebOptions options = {}, std::size_t plcs = 1,
                       std::function<void(std::string_view)> fault = {}) {
        for (std::size_t i = 0; i < plcs; ++i)
            plcs_.push_back(std::make_unique<plc::Plc>());
        web::WebContext context;
        for (std::size_t i = 0; i < plcs; ++i) {
            server::ControlTarget t;
            t.plc = plcs_[i].get();
            if (plcs > 1) t.name = "plc" + std::to_string(i + 1);
            t.addresses = {{static_cast<std::uint8_t>(i), 1}};
            context.targets.push_back(t);
        }
        options.port = 0;
        context.options = options;
        context.fault = std::move(fault);
        context.metrics = [] {
            return server::metrics::expose(server::metrics::process_metrics());
        };
        auto s = web::HttpServer::start(io_, std::move(context));
        EXPECT_TRUE(s) << s.error().message();
        server_ = std::move(*s);
        thread_ = std::thread([this] { io_.run(); });
    }
    ~WebServer() {
        on_io([this] { server_->stop(); });
        io_.stop();
        thread_.join();
    }
    std::uint16_t port() const { return server_->port(); }
    plc::Plc& plc(std::size_t i = 0) { return *plcs_[i]; }
    web::HttpServer& server() { return *server_; }

    // Runs `f` on the server's thread and waits for it.
    template <class F>
    auto on_io(F f) -> decltype(f()) {
        std::packaged_task<decltype(f())()> task(std::move(f));
        auto result = task.get_future();
        asio::post(io_, [&task] { task(); });
        EXPECT_EQ(result.wait_for(std::chrono::seconds(10)), std::future_status::ready);
        return result.get();
    }
    std::uint16_t word(Region region, std::size_t index, std::size_t plc_index = 0) {
        return on_io([&] { return plc(plc_index).memory().words(region)[index]; });
    }

  private:
    asio::io_context io_{1};
    std::vector<std::unique_ptr<plc::Plc>> plcs_;
    std::unique_ptr<web::HttpServer> server_;
    std::thread thread_;
};

// A blocking Beast client (each call bounded by the stream's deadline).
class HttpClient {
  public:
    explicit HttpClient(std::uint16_t port) : stream_(io_) {
        stream_.expires_after(std::chrono::seconds(10));
        stream_.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    }
    http::response<http::string_body> request(
        http::verb method, std::string target, std::string body = {},
        std::vector<std::pair<std::string, std::string>> headers = {}) {
        http::request<http::string_body> r{method, target, 11};
        r.set(http::field::host, "127.0.0.1");
        for (const auto& [k, v] : headers)
            r.set(k, v);
        if (!body.empty() || method == http::verb::post) {
            r.set(http::field::content_type, "application/json");
            r.body() = std::move(body);
            r.prepare_payload();
        }
        stream_.expires_after(std::chrono::seconds(10));
        http::write(stream_, r);
        return read();
    }
    // Sends raw bytes (malformed requests) and reads the answer.
    http::response<http::string_body> raw(const std::string& bytes) {
        stream_.expires_after(std::chrono::seconds(10));
        asio::write(stream_, asio::buffer(bytes));
        return read();
    }
    http::response<http::string_body> read() {
        http::response_parser<http::string_body> p;
        p.body_limit(16 * 1024 * 1024);
        stream_.expires_after(std::chrono::seconds(10));
        http::read(stream_, buffer_, p);
        return p.release();
    }
    // Sends `bytes` as far as the server takes them (it may close midway: a limit), then
    // reads whatever came back until the server closes: the answer's text, or "".
    std::string raw_until_closed(const std::string& bytes) {
        beast::error_code ec;
        stream_.expires_after(std::chrono::seconds(10));
        asio::write(stream_, asio::buffer(bytes), ec);
        std::string in;
        char chunk[4096];
        for (int i = 0; i < 1000; ++i) {
            stream_.expires_after(std::chrono::seconds(10));
            const auto n = stream_.read_some(asio::buffer(chunk), ec);
            in.append(chunk, n);
            if (ec) break;
        }
        return in;
    }
    // True when the server closed the connection (read returns end of stream).
    bool closed() {
        beast::error_code ec;
        char c;
        stream_.expires_after(std::chrono::seconds(10));
        stream_.read_some(asio::buffer(&c, 1), ec);
        return ec == asio::error::eof || ec == asio::error::connection_reset;
    }
    beast::tcp_stream& stream() { return stream_; }

  private:
    asio::io_context io_;
    beast::tcp_stream stream_;
    beast::flat_buffer buffer_;
};

inline nlohmann::json body_json(const http::response<http::string_body>& r) {
    return nlohmann::json::parse(r.body(), nullptr, false);
}

}  // namespace fins::test
