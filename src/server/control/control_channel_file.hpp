// The loopback control channel's file (issue 28; ControlTransport::loopback_tcp in
// control.hpp): where finsd's control channel listens when there are no Unix-domain
// sockets (Windows, and Wine, which has no AF_UNIX).
//
// finsd listens on 127.0.0.1 at an ephemeral port and writes one line to the channel file
// (the path a Unix socket would have): `<port> <token>\n`, the token 128 random bits as
// hex. The file is created exclusively, readable and writable by its owner only (Linux:
// mode 0600; Windows: a protected DACL granting the current user alone), and removed when
// the channel stops. Any local user can connect to a loopback port: the token is what
// proves a client could read the file. A client sends the token as its first line, then
// request lines as on the Unix socket; a first line that is not the token closes the
// connection without an answer.
//
// An existing file is replaced when it is stale (a finsd killed without removing it):
// empty, or naming a port on which nothing accepts a connection. One naming a port that
// accepts is refused (address in use: another finsd, or whatever took the port since);
// anything else there (a directory, a link, text that is not a channel line) is refused
// (file exists) and left alone.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <boost/asio/basic_socket_acceptor.hpp>
#include <boost/asio/generic/stream_protocol.hpp>

#include "fins/error.hpp"
#include "transport/asio.hpp"

namespace fins::server {

// The channel's listener, whichever its transport (control.cpp's sessions are generic too).
using ControlAcceptor = asio::basic_socket_acceptor<asio::generic::stream_protocol>;

struct ChannelFile {
    std::uint16_t port = 0;
    std::string token;
};

// `<port> <token>` (a trailing newline or CR LF allowed); nullopt for anything else: a
// port outside 1-65535, a token shorter than 16 or longer than 256 characters or with
// characters other than letters and digits, extra fields.
std::optional<ChannelFile> parse_channel_file(std::string_view text);

// Reads and parses the file: no such file, unreadable or not a channel line are errors
// (no_such_file_or_directory, the system's, invalid_argument).
Result<ChannelFile> read_channel_file(const std::filesystem::path& path);

// Binds `acceptor` to 127.0.0.1, an ephemeral port, listening; then makes the channel file
// at `path` naming it with `token` (replacing a stale one, as above).
Result<void> open_loopback_channel(ControlAcceptor& acceptor, const std::filesystem::path& path,
                                   const std::string& token);

}  // namespace fins::server
