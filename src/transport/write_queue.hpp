// Outgoing buffers of a transport: a FIFO of owned byte vectors whose storage is
// recycled, so steady traffic stops allocating once the pool has warmed up.
#pragma once

#include <cstdint>
#include <deque>
#include <vector>

#include "fins/byte_io.hpp"

namespace fins::transport {

class WriteQueue {
  public:
    // Appends one buffer holding `first` followed by `second`.
    void push(Bytes first, Bytes second = {}) {
        std::vector<std::uint8_t> buffer;
        if (!pool_.empty()) {
            buffer = std::move(pool_.back());
            pool_.pop_back();
        }
        buffer.assign(first.begin(), first.end());
        buffer.insert(buffer.end(), second.begin(), second.end());
        queue_.push_back(std::move(buffer));
    }
    [[nodiscard]] bool empty() const noexcept { return queue_.empty(); }
    [[nodiscard]] const std::vector<std::uint8_t>& front() const noexcept { return queue_.front(); }
    void pop() {
        // Keep a few buffers for reuse; an unusual burst should not pin memory forever.
        if (pool_.size() < max_pooled) pool_.push_back(std::move(queue_.front()));
        queue_.pop_front();
    }
    void clear() {
        while (!queue_.empty())
            pop();
    }

  private:
    static constexpr std::size_t max_pooled = 64;
    std::deque<std::vector<std::uint8_t>> queue_;
    std::vector<std::vector<std::uint8_t>> pool_;
};

}  // namespace fins::transport
