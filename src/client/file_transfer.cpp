// File memory helpers (22 01 / 22 02 / 22 03, W342 5-3-32 .. 5-3-34): whole
// directories and whole files over as many requests as they need, with a window of
// chunks kept in flight together like the split reads of helpers.cpp.
#include <algorithm>
#include <memory>

#include "fins/client.hpp"
#include "fins/commands/file_memory.hpp"

namespace fins {

namespace {

// 22 03 parameters before the data: disk, mode, name, position, length; after it the
// path length. The frame holds 2,012 bytes (header 10, command code 2).
constexpr std::size_t write_fixed = 2 + 2 + 12 + 4 + 2 + 2;

std::size_t write_chunk(const Client& client, const std::string& directory) noexcept {
    return client.max_parameters() - write_fixed - directory.size();
}
// 22 02 answer bytes before the data: file capacity, position, length (Ethernet: 1,988).
constexpr std::size_t read_fixed = 4 + 4 + 2;
std::uint16_t read_chunk(const Client& client) noexcept {
    return static_cast<std::uint16_t>(
        std::min<std::size_t>(max_file_read_bytes, client.max_response_data() - read_fixed));
}

// Keeps up to `window` requests in flight: `issue(i)` starts chunk i and must call
// `done()` from its completion.
struct Pipeline {
    std::size_t next = 0;
    std::size_t count = 0;
    std::size_t in_flight = 0;
    std::error_code error;
};

}  // namespace

Result<DirectoryListing> list_directory(Client& client, std::uint16_t disk,
                                        const std::string& directory) {
    DirectoryListing out;
    // 5-3-32: "add one to the number of response files when specifying the next
    // beginning file position" -- i.e. continue after the last entry returned.
    for (std::uint16_t first = 0;;) {
        const auto r = client.send(FileNameRead{disk, first, max_file_entries, directory});
        if (!r) return Unexpected(r.error());
        out.disk = r->disk;
        out.files.insert(out.files.end(), r->files.begin(), r->files.end());
        if (r->last || r->files.empty() || out.files.size() >= r->disk.total_files) break;
        first = static_cast<std::uint16_t>(first + r->files.size());
    }
    return out;
}

Result<std::vector<std::uint8_t>> get_file(Client& client, std::uint16_t disk,
                                           const std::string& directory, const FileName& file,
                                           const FileProgress& progress, std::size_t window) {
    const std::uint16_t chunk = read_chunk(client);
    const auto first = client.send(SingleFileRead{disk, file, 0, chunk, directory});
    if (!first) return Unexpected(first.error());
    const std::uint64_t size = first->file_size;
    auto data = std::make_shared<std::vector<std::uint8_t>>(static_cast<std::size_t>(size));
    std::copy(first->data.begin(), first->data.end(), data->begin());
    std::uint64_t done = first->data.size();
    if (progress) progress(done, size);
    if (first->last || done >= size) {
        data->resize(static_cast<std::size_t>(done));
        return std::move(*data);
    }
    auto p = std::make_shared<Pipeline>();
    p->next = 0;
    p->count = static_cast<std::size_t>((size - done + chunk - 1) / chunk);
    const std::uint64_t base = done;
    std::function<void()> issue = [&]() {
        while (!p->error && p->in_flight < std::max<std::size_t>(window, 1) && p->next < p->count) {
            const std::uint64_t offset = base + std::uint64_t{p->next} * chunk;
            const auto length =
                static_cast<std::uint16_t>(std::min<std::uint64_t>(chunk, size - offset));
            ++p->next;
            ++p->in_flight;
            client.async_send(
                SingleFileRead{disk, file, static_cast<std::uint32_t>(offset), length, directory},
                [&, offset, length](Result<SingleFileReadResponse> r) {
                    --p->in_flight;
                    if (!r) {
                        if (!p->error) p->error = r.error();
                        return;
                    }
                    if (r->data.size() != length || r->file_size != size) {
                        // The file changed under us, or the PLC answered short.
                        if (!p->error) p->error = make_error_code(ClientError::malformed_response);
                        return;
                    }
                    std::copy(r->data.begin(), r->data.end(),
                              data->begin() + static_cast<std::ptrdiff_t>(offset));
                    done += length;
                    if (progress) progress(done, size);
                    issue();
                });
        }
    };
    issue();
    client.run();
    if (p->error) return Unexpected(p->error);
    return std::move(*data);
}

Result<void> put_file(Client& client, std::uint16_t disk, const std::string& directory,
                      const FileName& file, std::span<const std::uint8_t> data, bool replace,
                      const FileProgress& progress, std::size_t window) {
    const std::size_t chunk = write_chunk(client, directory);
    const auto first_size = std::min(chunk, data.size());
    const auto mode = replace ? FileWriteMode::create_or_replace : FileWriteMode::create;
    if (auto r = client.send(SingleFileWrite{disk, static_cast<std::uint16_t>(mode), file, 0,
                                             data.first(first_size), directory});
        !r)
        return Unexpected(r.error());
    std::uint64_t done = first_size;
    if (progress) progress(done, data.size());
    auto p = std::make_shared<Pipeline>();
    p->count = (data.size() - first_size + chunk - 1) / chunk;
    // In order on one link, so each 0003 lands exactly at the file's end: the server
    // extends the file without rewriting it.
    std::function<void()> issue = [&]() {
        while (!p->error && p->in_flight < std::max<std::size_t>(window, 1) && p->next < p->count) {
            const std::size_t offset = first_size + p->next * chunk;
            const auto n = std::min(chunk, data.size() - offset);
            ++p->next;
            ++p->in_flight;
            client.async_send(
                SingleFileWrite{disk, static_cast<std::uint16_t>(FileWriteMode::overwrite), file,
                                static_cast<std::uint32_t>(offset), data.subspan(offset, n),
                                directory},
                [&, n](Result<EmptyResponse> r) {
                    --p->in_flight;
                    if (!r) {
                        if (!p->error) p->error = r.error();
                        return;
                    }
                    done += n;
                    if (progress) progress(done, data.size());
                    issue();
                });
        }
    };
    issue();
    client.run();
    if (p->error) return Unexpected(p->error);
    return {};
}

}  // namespace fins
