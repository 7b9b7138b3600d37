// The ownership seam: which PLCs this bridge instance polls and writes.
//
// The bridge asks owns(plc) before it starts polling a PLC and again before it executes
// a write; a write for a PLC it does not own is not executed and not answered (its
// owner answers). When membership changes (an instance joins or dies), the Ownership
// implementation calls the handler given to on_change(); the bridge then starts polling
// the PLCs it newly owns and stops those it lost (Bridge::reconcile()).
//
// SingleInstance owns everything. The multi-instance implementation (rendezvous hashing
// over the live members seen on {prefix}/$bridge/+/status) plugs in here.
#pragma once

#include <functional>
#include <string_view>

namespace fins::bridge {

class Ownership {
  public:
    virtual ~Ownership() = default;
    // Called on the bridge's io_context thread.
    [[nodiscard]] virtual bool owns(std::string_view plc) const = 0;
    // The handler runs on the bridge's io_context thread (post to it from elsewhere).
    void on_change(std::function<void()> handler) { changed_ = std::move(handler); }

  protected:
    void changed() const {
        if (changed_) changed_();
    }

  private:
    std::function<void()> changed_;
};

class SingleInstance final : public Ownership {
  public:
    [[nodiscard]] bool owns(std::string_view) const override { return true; }
};

}  // namespace fins::bridge
