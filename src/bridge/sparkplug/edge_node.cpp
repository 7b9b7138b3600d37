#include "bridge/sparkplug/edge_node.hpp"

#include <cassert>
#include <utility>

namespace fins::bridge::sparkplug {
namespace pb = finskit::sparkplug::pb;

namespace {

// Device metric aliases: device k (in order of definition, from 1) owns aliases
// k << 20 .. (k << 20) + 2^20 - 1, so an alias is unique across the Edge Node (chapter 6,
// "alias") and stays the same across rebirths and ownership moves within one process.
constexpr unsigned alias_shift = 20;
[[maybe_unused]] constexpr std::size_t max_metrics_per_device = std::size_t{1} << alias_shift;

void add_node_metric_bool(PbPayload& p, std::string_view name, bool v, std::uint64_t ts) {
    auto* m = p.add_metrics();
    m->set_name(std::string(name));
    m->set_timestamp(ts);
    m->set_datatype(pb::Boolean);
    m->set_boolean_value(v);
}

void add_bdseq(PbPayload& p, std::uint64_t bd_seq, std::uint64_t ts) {
    auto* m = p.add_metrics();
    m->set_name(std::string(bdseq_metric));
    m->set_timestamp(ts);
    m->set_datatype(pb::Int64);
    m->set_long_value(bd_seq);
}

}  // namespace

EdgeNode::EdgeNode(std::string group_id, std::string edge_node_id)
    : group_id_(std::move(group_id)), edge_node_id_(std::move(edge_node_id)) {
    assert(!group_id_.empty() && !edge_node_id_.empty());
}

std::string EdgeNode::topic(std::string_view verb, std::string_view device) const {
    std::string t;
    t.reserve(namespace_v1.size() + group_id_.size() + verb.size() + edge_node_id_.size() +
              device.size() + 4);
    t.append(namespace_v1)
        .append("/")
        .append(group_id_)
        .append("/")
        .append(verb)
        .append("/")
        .append(edge_node_id_);
    if (!device.empty()) t.append("/").append(device);
    return t;
}

std::uint64_t EdgeNode::take_seq() noexcept {
    const std::uint64_t s = seq_;
    seq_ = static_cast<std::uint8_t>(seq_ + 1);  // 255 -> 0 (chapter 6: seq never exceeds 255)
    return s;
}

void EdgeNode::finish(std::string t, int qos, std::vector<Message>& out) {
    Message m;
    m.topic = std::move(t);
    m.qos = qos;
    m.retain = false;  // no Sparkplug message of an Edge Node is retained
    scratch_.SerializeToString(&m.payload);
    out.push_back(std::move(m));
}

Message EdgeNode::next_will(std::uint64_t now_ms) {
    // bdSeq starts at 0 and steps by one per CONNECT, 255 -> 0 (chapter 5, "Edge Node Session
    // Establishment").
    if (have_will_) bd_seq_ = (bd_seq_ + 1) % 256;
    have_will_ = true;
    return death(now_ms);
}

Message EdgeNode::death(std::uint64_t now_ms) const {
    PbPayload p;
    p.set_timestamp(now_ms);
    add_bdseq(p, bd_seq_, now_ms);
    Message m;
    m.topic = topic("NDEATH");
    m.qos = 1;  // the Will is QoS 1, not retained; NDEATH carries no seq
    m.retain = false;
    p.SerializeToString(&m.payload);
    return m;
}

std::vector<std::string> EdgeNode::subscriptions() const {
    return {topic("NCMD"), topic("DCMD") + "/+"};
}

void EdgeNode::define_device(const std::string& name, std::vector<MetricDef> metrics) {
    assert(metrics.size() < max_metrics_per_device);
    Device d;
    d.alias_base = next_alias_base_++ << alias_shift;
    d.last.assign(metrics.size(), std::monostate{});
    d.last_ts.assign(metrics.size(), 0);
    d.metrics = std::move(metrics);
    devices_.insert_or_assign(name, std::move(d));
}

const EdgeNode::Device* EdgeNode::find(std::string_view name) const {
    const auto it = devices_.find(name);
    return it == devices_.end() ? nullptr : &it->second;
}

bool EdgeNode::attached(const std::string& device) const {
    const auto* d = find(device);
    return d && d->attached;
}

void EdgeNode::birth(std::uint64_t now_ms, std::vector<Message>& out) {
    // NBIRTH: seq 0, the Will's bdSeq, "Node Control/Rebirth" false with no alias.
    seq_ = 0;
    scratch_.Clear();
    scratch_.set_timestamp(now_ms);
    scratch_.set_seq(take_seq());
    add_bdseq(scratch_, bd_seq_, now_ms);
    add_node_metric_bool(scratch_, rebirth_metric, false, now_ms);
    finish(topic("NBIRTH"), 0, out);
    born_ = true;
    for (auto& [name, d] : devices_)
        if (d.attached) device_birth(name, d, now_ms, out);
}

void EdgeNode::device_birth(const std::string& name, Device& d, std::uint64_t now_ms,
                            std::vector<Message>& out) {
    scratch_.Clear();
    scratch_.set_timestamp(now_ms);
    scratch_.set_seq(take_seq());
    for (std::size_t i = 0; i < d.metrics.size(); ++i) {
        auto* m = scratch_.add_metrics();
        m->set_name(d.metrics[i].name);
        m->set_alias(d.alias_base + i);
        m->set_datatype(static_cast<std::uint32_t>(d.metrics[i].datatype));
        m->set_timestamp(d.last_ts[i] ? d.last_ts[i] : now_ms);
        encode_value(*m, d.metrics[i].datatype, d.last[i]);
        if (d.metrics[i].writable) {
            // Tell host applications which metrics accept a DCMD (a custom property; hosts that do
            // not know it ignore it).
            auto* props = m->mutable_properties();
            props->add_keys("writable");
            auto* v = props->add_values();
            v->set_type(pb::Boolean);
            v->set_boolean_value(true);
        }
    }
    finish(topic("DBIRTH", name), 0, out);
}

void EdgeNode::attach(const std::string& device, std::uint64_t now_ms, std::vector<Message>& out) {
    const auto it = devices_.find(device);
    if (it == devices_.end() || it->second.attached) return;
    it->second.attached = true;
    if (born_) device_birth(device, it->second, now_ms, out);
}

void EdgeNode::detach(const std::string& device, std::uint64_t now_ms, std::vector<Message>& out) {
    const auto it = devices_.find(device);
    if (it == devices_.end() || !it->second.attached) return;
    it->second.attached = false;
    // The values were this owner's view; another owner births the device with its own.
    std::fill(it->second.last.begin(), it->second.last.end(), MetricValue{});
    std::fill(it->second.last_ts.begin(), it->second.last_ts.end(), 0);
    if (!born_) return;
    scratch_.Clear();
    scratch_.set_timestamp(now_ms);
    scratch_.set_seq(take_seq());
    finish(topic("DDEATH", device), 0, out);
}

void EdgeNode::data(const std::string& device, std::span<const MetricUpdate> updates,
                    std::uint64_t now_ms, std::vector<Message>& out) {
    const auto it = devices_.find(device);
    if (it == devices_.end() || updates.empty()) return;
    auto& d = it->second;
    for (const auto& u : updates) {
        if (u.index >= d.metrics.size()) continue;
        d.last[u.index] = u.value;
        d.last_ts[u.index] = u.timestamp_ms;
    }
    if (!born_ || !d.attached) return;  // kept for the DBIRTH
    scratch_.Clear();
    scratch_.set_timestamp(now_ms);
    scratch_.set_seq(take_seq());
    for (const auto& u : updates) {
        if (u.index >= d.metrics.size()) continue;
        auto* m = scratch_.add_metrics();
        m->set_alias(d.alias_base + u.index);  // DATA carries the alias only
        m->set_timestamp(u.timestamp_ms);
        encode_value(*m, d.metrics[u.index].datatype, u.value);
    }
    finish(topic("DDATA", device), 0, out);
}

void EdgeNode::on_command(std::string_view t, std::string_view payload,
                          std::vector<Command>& out) const {
    const auto parts = parse_topic(t);
    if (!parts || parts->group_id != group_id_ || parts->edge_node_id != edge_node_id_) {
        out.emplace_back(CommandError{"not a command topic of this Edge Node: " + std::string(t)});
        return;
    }
    PbPayload p;
    if (!p.ParseFromArray(payload.data(), static_cast<int>(payload.size()))) {
        out.emplace_back(CommandError{"the payload is not a Sparkplug B protobuf"});
        return;
    }
    if (parts->verb == "NCMD" && parts->device_id.empty()) {
        bool any = false;
        for (const auto& m : p.metrics()) {
            if (m.name() == rebirth_metric) {
                any = true;
                if (m.value_case() == PbMetric::kBooleanValue && m.boolean_value())
                    out.emplace_back(Rebirth{});
                else
                    out.emplace_back(CommandError{"Node Control/Rebirth must be the Boolean true"});
            }
        }
        if (!any) out.emplace_back(CommandError{"NCMD names no metric this Edge Node knows"});
        return;
    }
    if (parts->verb != "DCMD" || parts->device_id.empty()) {
        out.emplace_back(CommandError{"not an NCMD or DCMD: " + std::string(t)});
        return;
    }
    const std::string device(parts->device_id);
    const auto* d = find(device);
    if (!d) {
        out.emplace_back(CommandError{"no device " + device});
        return;
    }
    if (!d->attached) {
        // Another instance owns it now: its DBIRTH went out under that instance's Edge Node.
        out.emplace_back(CommandError{"device " + device + " is not published by this Edge Node"});
        return;
    }
    for (const auto& m : p.metrics()) {
        std::optional<std::size_t> index;
        if (m.has_alias()) {
            if (m.alias() >= d->alias_base && m.alias() - d->alias_base < d->metrics.size())
                index = static_cast<std::size_t>(m.alias() - d->alias_base);
        } else if (m.has_name()) {
            for (std::size_t i = 0; i < d->metrics.size(); ++i)
                if (d->metrics[i].name == m.name()) index = i;
        }
        if (!index) {
            out.emplace_back(
                CommandError{"device " + device + " has no metric " +
                             (m.has_alias() ? "alias " + std::to_string(m.alias()) : m.name())});
            continue;
        }
        const auto& def = d->metrics[*index];
        if (!def.writable) {
            out.emplace_back(CommandError{def.name + " is not writable"});
            continue;
        }
        std::string why;
        auto v = decode_value(m, def.datatype, &why);
        if (std::holds_alternative<std::monostate>(v)) {
            out.emplace_back(CommandError{def.name + ": " + why});
            continue;
        }
        out.emplace_back(DeviceWrite{device, *index, def.name, std::move(v)});
    }
}

std::optional<TopicParts> parse_topic(std::string_view t) {
    std::string_view parts[5];
    std::size_t n = 0;
    while (n < 5) {
        const auto slash = t.find('/');
        parts[n++] = t.substr(0, slash);
        if (slash == std::string_view::npos) {
            t = {};
            break;
        }
        t.remove_prefix(slash + 1);
        if (n == 5) return std::nullopt;  // more levels than a Sparkplug topic has
    }
    if (n < 4 || parts[0] != namespace_v1) return std::nullopt;
    for (std::size_t i = 0; i < n; ++i)
        if (parts[i].empty()) return std::nullopt;
    return TopicParts{parts[1], parts[2], parts[3], n == 5 ? parts[4] : std::string_view{}};
}

}  // namespace fins::bridge::sparkplug
