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
#include <string>
#include <string_view>
#include <vector>

namespace fins::bridge {

class Ownership {
  public:
    virtual ~Ownership() = default;
    // Called on the bridge's io_context thread.
    [[nodiscard]] virtual bool owns(std::string_view plc) const = 0;
    // Membership travels on the bridge's MQTT connection (bridge/cluster): the topic filters
    // to subscribe to, every message received (true: it was membership, consumed), and the
    // loss of the connection. All on the io_context thread.
    [[nodiscard]] virtual std::vector<std::string> subscriptions() const { return {}; }
    virtual bool on_message(std::string_view topic, std::string_view payload) {
        (void)topic;
        (void)payload;
        return false;
    }
    virtual void connection_lost() {}
    // Whether this instance knows the members and may decide what it owns: commands that
    // arrive before (a persistent session's queued writes come right after CONNACK) wait.
    [[nodiscard]] virtual bool joined() const { return true; }
    // Whether this instance owns plc once it has joined (counted as a member even before
    // that): who answers a retained command, which is refused and never executed.
    [[nodiscard]] virtual bool owns_once_joined(std::string_view plc) const { return owns(plc); }
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
