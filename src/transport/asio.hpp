#pragma once
// finskit runs every socket, timer and serial port on Boost.Asio (libboost1.81-dev), so
// that Beast's HTTP and WebSocket sessions share the same io_context as FINS. This alias
// is the one place that says so: code writes `asio::` and reads as it did on standalone Asio.
namespace boost::asio {}
namespace asio = boost::asio;
