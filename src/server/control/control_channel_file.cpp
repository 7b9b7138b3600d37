// The loopback control channel's file (contract in control_channel_file.hpp).
#include "server/control/control_channel_file.hpp"

#ifdef _WIN32
#include <sddl.h>
#include <windows.h>
#include <winsock2.h>
#else
#include <fcntl.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <fmt/core.h>
#include <boost/asio/ip/tcp.hpp>

namespace fins::server {

namespace {

constexpr std::size_t min_token_size = 16;
constexpr std::size_t max_token_size = 256;
// A channel line is short: a longer file is not one.
constexpr std::size_t max_file_size = 512;

std::error_code errc(std::errc e) {
    return std::make_error_code(e);
}

#ifdef _WIN32
std::error_code last_error() {
    return boost::system::error_code(static_cast<int>(::GetLastError()),
                                     boost::system::system_category());
}

// "D:P(A;;FA;;;<the current user's SID>)": full access for the user, no one else, nothing
// inherited from the directory.
Result<std::wstring> user_only_sddl() {
    HANDLE process_token = nullptr;
    if (!::OpenProcessToken(::GetCurrentProcess(), TOKEN_QUERY, &process_token))
        return Unexpected(last_error());
    DWORD size = 0;
    ::GetTokenInformation(process_token, TokenUser, nullptr, 0, &size);
    std::vector<unsigned char> user(std::max<DWORD>(size, sizeof(TOKEN_USER)));
    const bool got = ::GetTokenInformation(process_token, TokenUser, user.data(),
                                           static_cast<DWORD>(user.size()), &size) != 0;
    const auto why = last_error();
    ::CloseHandle(process_token);
    if (!got) return Unexpected(why);
    LPWSTR sid = nullptr;
    if (!::ConvertSidToStringSidW(reinterpret_cast<TOKEN_USER*>(user.data())->User.Sid, &sid))
        return Unexpected(last_error());
    std::wstring sddl = L"D:P(A;;FA;;;" + std::wstring(sid) + L")";
    ::LocalFree(sid);
    return sddl;
}

Result<void> write_exclusive(const std::filesystem::path& path, const std::string& text) {
    const auto sddl = user_only_sddl();
    if (!sddl) return Unexpected(sddl.error());
    PSECURITY_DESCRIPTOR descriptor = nullptr;
    if (!::ConvertStringSecurityDescriptorToSecurityDescriptorW(sddl->c_str(), SDDL_REVISION_1,
                                                                &descriptor, nullptr))
        return Unexpected(last_error());
    SECURITY_ATTRIBUTES attributes{sizeof attributes, descriptor, FALSE};
    HANDLE file = ::CreateFileW(path.c_str(), GENERIC_WRITE, 0, &attributes, CREATE_NEW,
                                FILE_ATTRIBUTE_NORMAL, nullptr);
    const auto why = last_error();
    ::LocalFree(descriptor);
    if (file == INVALID_HANDLE_VALUE) return Unexpected(why);
    DWORD written = 0;
    const bool ok =
        ::WriteFile(file, text.data(), static_cast<DWORD>(text.size()), &written, nullptr) != 0 &&
        written == text.size();
    const auto write_why = last_error();
    ::CloseHandle(file);
    if (ok) return {};
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    return Unexpected(write_why);
}

// Without it another program could bind the same port with SO_REUSEADDR and take the
// connections, tokens included.
Result<void> exclusive_port(ControlAcceptor& acceptor) {
    const BOOL on = TRUE;
    if (::setsockopt(acceptor.native_handle(), SOL_SOCKET, static_cast<int>(SO_EXCLUSIVEADDRUSE),
                     reinterpret_cast<const char*>(&on), sizeof on) != 0)
        return Unexpected(
            boost::system::error_code(::WSAGetLastError(), boost::system::system_category()));
    return {};
}
#else
Result<void> write_exclusive(const std::filesystem::path& path, const std::string& text) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    if (fd < 0) return Unexpected(std::error_code(errno, std::generic_category()));
    std::size_t done = 0;
    while (done < text.size()) {
        const auto n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        done += static_cast<std::size_t>(n);
    }
    const std::error_code why(errno, std::generic_category());
    ::close(fd);
    if (done == text.size()) return {};
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    return Unexpected(why);
}

Result<void> exclusive_port(ControlAcceptor&) {
    return {};  // Linux never lets another user's socket share a bound port
}
#endif

bool token_character(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0;
}

Result<std::string> read_text(const std::filesystem::path& path) {
    std::error_code ec;
    const auto st = std::filesystem::symlink_status(path, ec);
    if (!std::filesystem::exists(st)) return Unexpected(errc(std::errc::no_such_file_or_directory));
    if (!std::filesystem::is_regular_file(st)) return Unexpected(errc(std::errc::file_exists));
    std::ifstream in(path, std::ios::binary);
    if (!in) return Unexpected(errc(std::errc::permission_denied));
    std::string text;
    char c = 0;
    while (text.size() <= max_file_size && in.get(c))
        text.push_back(c);
    return text;
}

// An existing file at `path`: removed when stale, else why it stays.
Result<void> clear_stale(ControlAcceptor& acceptor, const std::filesystem::path& path) {
    auto text = read_text(path);
    if (!text && text.error() == errc(std::errc::no_such_file_or_directory)) return {};
    if (!text) return Unexpected(text.error());
    if (!text->empty()) {  // empty: finsd was killed between creating and writing it
        const auto channel = parse_channel_file(*text);
        if (!channel) return Unexpected(errc(std::errc::file_exists));
        asio::ip::tcp::socket probe(acceptor.get_executor());
        boost::system::error_code ec;
        probe.connect({asio::ip::address_v4::loopback(), channel->port}, ec);
        if (!ec) return Unexpected(errc(std::errc::address_in_use));
    }
    std::error_code ec;
    std::filesystem::remove(path, ec);
    if (ec) return Unexpected(ec);
    return {};
}

}  // namespace

std::optional<ChannelFile> parse_channel_file(std::string_view text) {
    if (!text.empty() && text.back() == '\n') text.remove_suffix(1);
    if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
    const auto space = text.find(' ');
    if (space == std::string_view::npos) return std::nullopt;
    const auto port_text = text.substr(0, space);
    const auto token = text.substr(space + 1);
    unsigned port = 0;
    const auto [end, ec] =
        std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
    if (ec != std::errc{} || end != port_text.data() + port_text.size() || port == 0 ||
        port > 65535)
        return std::nullopt;
    if (token.size() < min_token_size || token.size() > max_token_size ||
        !std::all_of(token.begin(), token.end(), token_character))
        return std::nullopt;
    return ChannelFile{static_cast<std::uint16_t>(port), std::string(token)};
}

Result<ChannelFile> read_channel_file(const std::filesystem::path& path) {
    const auto text = read_text(path);
    if (!text) return Unexpected(text.error());
    auto channel = parse_channel_file(*text);
    if (!channel) return Unexpected(errc(std::errc::invalid_argument));
    return std::move(*channel);
}

Result<void> open_loopback_channel(ControlAcceptor& acceptor, const std::filesystem::path& path,
                                   const std::string& token) {
    if (path.empty() || token.size() < min_token_size || token.size() > max_token_size ||
        !std::all_of(token.begin(), token.end(), token_character))
        return Unexpected(errc(std::errc::invalid_argument));
    if (auto cleared = clear_stale(acceptor, path); !cleared) return cleared;
    const asio::generic::stream_protocol::endpoint endpoint(
        asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(), 0));
    boost::system::error_code ec;
    if (acceptor.open(endpoint.protocol(), ec); ec) return Unexpected(ec);
    if (auto exclusive = exclusive_port(acceptor); !exclusive) return exclusive;
    if (acceptor.bind(endpoint, ec); ec) return Unexpected(ec);
    if (acceptor.listen(asio::socket_base::max_listen_connections, ec); ec) return Unexpected(ec);
    const auto local = acceptor.local_endpoint(ec);
    if (ec) return Unexpected(ec);
    asio::ip::tcp::endpoint bound;
    if (local.size() > bound.capacity()) return Unexpected(errc(std::errc::invalid_argument));
    std::memcpy(bound.data(), local.data(), local.size());
    bound.resize(local.size());
    return write_exclusive(path, fmt::format("{} {}\n", bound.port(), token));
}

}  // namespace fins::server
