// File memory helpers (22 01 / 22 02 / 22 03, W342 5-3-32 .. 5-3-34): whole
// directories and whole files over as many requests as they need, with a window of
// chunks kept in flight together like the split reads of helpers.cpp.
#include <algorithm>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "engine/request_tracker.hpp"  // default_quarantine_timeouts
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

namespace {

// The 22 03 0003 chunks of one pass of put_file(), from `base` to the end of the data.
// Every chunk is written at its explicit position, so a retransmitted or duplicated
// chunk writes the same bytes at the same place again and never appends twice (0002
// would). A chunk that reaches the PLC before the one in front of it (that one lost or
// delayed) is refused 1103, position past the file's end: it waits and is sent again
// once every chunk before it is acknowledged. Refused again at the file's acknowledged
// end, the file is shorter than acknowledged (a late copy of the creating request
// truncated it): the pass stops and put_file() resumes from the size 22 02 reports.
class ChunkWriter {
  public:
    ChunkWriter(Client& client, std::uint16_t disk, const std::string& directory,
                const FileName& file, std::span<const std::uint8_t> data, std::uint64_t base,
                std::size_t chunk, std::size_t window, const FileProgress& progress)
        : client_(client),
          disk_(disk),
          directory_(directory),
          file_(file),
          data_(data),
          base_(base),
          chunk_(chunk),
          window_(std::max<std::size_t>(window, 1)),
          progress_(progress),
          count_((data.size() - base + chunk - 1) / chunk),
          acked_(count_),
          refusals_(count_) {}

    // Runs the pass; an error other than a refused early chunk ends it. A pass that
    // stopped because the file is shorter than acknowledged returns normally: the size
    // check after it finds out.
    Result<void> run() {
        issue();
        client_.run();
        if (error_) return Unexpected(error_);
        return {};
    }

  private:
    void issue() {
        while (!error_ && !short_file_ && in_flight_ < window_) {
            std::size_t i = 0;
            if (!again_.empty()) {  // lowest first: it may unblock the others
                i = again_.front();
                again_.erase(again_.begin());
            } else if (next_ < count_) {
                i = next_++;
            } else {
                return;
            }
            send(i);
        }
    }

    void send(std::size_t i) {
        const std::uint64_t offset = base_ + std::uint64_t{i} * chunk_;
        const auto n =
            static_cast<std::size_t>(std::min<std::uint64_t>(chunk_, data_.size() - offset));
        ++in_flight_;
        client_.async_send(
            SingleFileWrite{disk_, static_cast<std::uint16_t>(FileWriteMode::overwrite), file_,
                            static_cast<std::uint32_t>(offset),
                            data_.subspan(static_cast<std::size_t>(offset), n), directory_},
            [this, i, n](Result<EmptyResponse> r) { done(i, n, r); });
    }

    void done(std::size_t i, std::size_t n, const Result<EmptyResponse>& r) {
        --in_flight_;
        if (r) {
            acked_[i] = true;
            written_ += n;
            if (progress_) progress_(base_ + written_, data_.size());
            const auto before = prefix_;
            while (prefix_ < count_ && acked_[prefix_])
                ++prefix_;
            // The chunks refused while one before them was missing may land now.
            if (prefix_ != before) release_waiting();
        } else if (r.error() == make_error_code(EndCode::address_range_error)) {
            if (i > prefix_) {
                waiting_.push_back(i);
            } else if (refusals_[i]++ == 0) {
                // The answer may be a late one, to an attempt sent before the chunk in
                // front was written: a fresh attempt tells.
                insert_again(i);
            } else {
                short_file_ = true;
            }
        } else if (!error_) {
            error_ = r.error();
        }
        issue();
    }

    void release_waiting() {
        for (const auto i : waiting_)
            insert_again(i);
        waiting_.clear();
    }
    void insert_again(std::size_t i) {
        again_.insert(std::upper_bound(again_.begin(), again_.end(), i), i);
    }

    Client& client_;
    std::uint16_t disk_;
    const std::string& directory_;
    const FileName& file_;
    std::span<const std::uint8_t> data_;
    std::uint64_t base_;
    std::size_t chunk_;
    std::size_t window_;
    const FileProgress& progress_;
    std::size_t count_;
    std::vector<bool> acked_;
    std::vector<std::uint8_t> refusals_;  // 1103 answers at the acknowledged end
    std::vector<std::size_t> again_;      // sorted: chunks to send again, lowest first
    std::vector<std::size_t> waiting_;    // refused while a chunk before them was missing
    std::size_t next_ = 0;                // the first chunk never sent
    std::size_t prefix_ = 0;              // chunks [0, prefix_) acknowledged
    std::size_t in_flight_ = 0;
    std::uint64_t written_ = 0;
    std::error_code error_;
    bool short_file_ = false;
};

// How long a copy of a request may still arrive after its last attempt: the bound the
// client puts on late answers (its SID quarantine, ClientOptions::sid_quarantine).
std::chrono::nanoseconds datagram_lifetime(const ClientOptions& o) {
    if (o.sid_quarantine.count() > 0) return o.sid_quarantine;
    return o.timeout * default_quarantine_timeouts;
}

}  // namespace

Result<void> put_file(Client& client, std::uint16_t disk, const std::string& directory,
                      const FileName& file, std::span<const std::uint8_t> data, bool replace,
                      const FileProgress& progress, std::size_t window) {
    const std::size_t chunk = write_chunk(client, directory);
    const auto first_size = std::min(chunk, data.size());
    const auto mode = replace ? FileWriteMode::create_or_replace : FileWriteMode::create;
    const auto retransmitted = client.stats().retransmitted;
    const auto created = client.send(SingleFileWrite{disk, static_cast<std::uint16_t>(mode), file,
                                                     0, data.first(first_size), directory});
    const bool create_resent = client.stats().retransmitted != retransmitted;
    const auto created_at = std::chrono::steady_clock::now();
    if (!created) {
        // 2107 to a retransmitted 0000: the first attempt may have created the file and
        // lost its answer. It did if the file holds exactly the first chunk.
        if (created.error() != make_error_code(EndCode::file_name_exists) || replace ||
            !create_resent)
            return Unexpected(created.error());
        const auto check = client.send(SingleFileRead{
            disk, file, 0,
            static_cast<std::uint16_t>(std::min<std::size_t>(first_size, read_chunk(client))),
            directory});
        if (!check || check->file_size != first_size || first_size > check->data.size() ||
            !std::equal(check->data.begin(), check->data.end(), data.begin()))
            return Unexpected(created.error());
    }
    if (progress) progress(first_size, data.size());
    if (first_size == data.size()) return {};

    // The rest goes in passes of 0003 chunks (ChunkWriter). Every write puts data[i] at
    // position i of the file this transfer created, so the file is always a prefix of the
    // data, and its size alone (22 02, position 0, length 0) says whether the transfer is
    // complete and where to resume.
    constexpr int max_passes = 8;
    std::uint64_t size = first_size;
    for (int pass = 0; pass < max_passes; ++pass) {
        if (size < data.size()) {
            ChunkWriter writer(client, disk, directory, file, data, size, chunk, window, progress);
            if (auto r = writer.run(); !r) return r;
        }
        // A late copy of a retransmitted 0001 would truncate the file to the first chunk
        // after the check: wait until no copy can still be on its way (the same bound the
        // client puts on late answers) before checking.
        if (replace && create_resent) {
            const auto until = created_at + datagram_lifetime(client.options());
            if (std::chrono::steady_clock::now() < until) std::this_thread::sleep_until(until);
        }
        const auto stat = client.send(SingleFileRead{disk, file, 0, 0, directory});
        if (!stat) return Unexpected(stat.error());
        if (stat->file_size == data.size()) return {};
        // Longer than the data: another writer; the file is not what was sent.
        if (stat->file_size > data.size())
            return Unexpected(make_error_code(EndCode::data_mismatch));
        size = stat->file_size;
    }
    return Unexpected(make_error_code(EndCode::address_range_error));
}

}  // namespace fins
