#include "replay/replay_report.h"
#include "report_format.h"

#include <cmath>
#include <cstdio>

#include "epichead/firmware_iface/head_status.h"
#include "epichead/firmware_iface/heartbeat.h"

namespace epichead::tools::replay {

namespace fw = firmware_iface;
using nlohmann::json;

namespace {

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json gap_json(const GapStats& g) {
  if (g.count() == 0) return nullptr;
  return {{"p50", g.percentile(0.5)}, {"p99", g.percentile(0.99)}, {"max", g.max()}};
}

json timing_json(const StreamStats& s, double log_span_s) {
  json j{{"count", s.count()}};
  j["rate_hz"] = s.timed() ? json(s.rate_hz()) : json(nullptr);
  j["gap_us"] = gap_json(s.gaps_us());
  j["jitter_us"] = gap_json(s.jitter_us());
  j["nominal_period_us"] = s.nominal_period_us() >= 0 ? json(s.nominal_period_us()) : json(nullptr);
  j["bus_load"] = log_span_s > 0 ? json(s.bus_s() / log_span_s) : json(nullptr);
  if (s.backwards() > 0) j["stamps_backwards"] = s.backwards();
  return j;
}

std::string fmt(double v, const char* f = "%.1f") { return format_number(v, f); }

std::string gap_text(const GapStats& g) {
  if (g.count() == 0) return "-";
  return fmt(g.percentile(0.5), "%.0f") + "/" + fmt(g.percentile(0.99), "%.0f") + "/" + fmt(g.max(), "%.0f");
}

double span_s(const LogAnalyzer& a) { return a.timed() ? a.last_s() - a.first_s() : 0; }

}  // namespace

json report_json(const ReadSummary& read, const LogAnalyzer& a) {
  const double span = span_s(a);
  json j;
  j["log"] = read.path;
  j["lines"] = read.lines;
  j["frames"] = a.frames();
  j["malformed_lines"] = read.malformed;
  j["first_errors"] = read.first_errors;
  j["timestamps"] = a.frames_without_stamp() == 0 ? "all" : (a.timed() ? "some" : "none");
  j["start_s"] = a.timed() ? json(a.first_s()) : json(nullptr);
  j["duration_s"] = a.timed() ? json(span) : json(nullptr);
  j["bitrate"] = a.options().bitrate;
  j["data_bitrate"] = a.options().data_bitrate;
  j["bus_load"] = number(a.bus_load());
  j["error_frames"] = a.error_frames();
  j["protocol_frames"] = a.protocol_frames();
  j["unknown_frames"] = a.unknown_frames();
  j["unknown_ids"] = a.unknown_ids();
  if (a.ids_over_limit() > 0) j["frames_of_ids_over_table_limit"] = a.ids_over_limit();

  json ids = json::array();
  for (const IdStats* s : a.ids()) {
    json e = timing_json(s->timing, span);
    e["id"] = hex_id(s->id, s->extended);
    e["extended"] = s->extended;
    e["bytes"] = s->bytes;
    if (s->remote) e["remote"] = s->remote;
    if (s->fd) e["fd"] = s->fd;
    const auto ours = s->extended ? std::nullopt : fw::classify_id(s->id);
    e["message"] = ours ? json(std::string(fw::to_string(ours->type))) : json(nullptr);
    ids.push_back(e);
  }
  j["ids"] = ids;

  json messages = json::object();
  for (int t = 0; t < fw::kMessageTypeCount; ++t) {
    const auto type = static_cast<fw::MessageType>(t);
    const MessageStats& m = a.message(type);
    if (m.timing.count() == 0) continue;
    json e = timing_json(m.timing, span);
    e["decoded"] = m.decoded;
    json errors = json::object();
    for (int k = 0; k < kWireErrorKinds; ++k)
      if (m.errors[static_cast<std::size_t>(k)] > 0)
        errors[std::string(fw::to_string(static_cast<fw::WireErrorKind>(k)))] = m.errors[static_cast<std::size_t>(k)];
    e["decode_errors"] = errors;
    e["out_of_range"] = m.errors[static_cast<std::size_t>(fw::WireErrorKind::OutOfRange)];
    e["saturated_frames"] = m.saturated_frames;
    if (type != fw::MessageType::TimeSyncRequest && type != fw::MessageType::TimeSyncReply &&
        type != fw::MessageType::Heartbeat) {
      e["counter_lost"] = m.counter.lost();
      e["counter_duplicates"] = m.counter.duplicates();
    }
    if (m.device_gaps_us.count() > 0) e["device_gap_us"] = gap_json(m.device_gaps_us);
    messages[std::string(fw::to_string(type))] = e;
  }
  j["messages"] = messages;

  json faults = json::object();
  for (int bit = 0; bit < 16; ++bit) {
    const FaultInfo& f = a.faults()[static_cast<std::size_t>(bit)];
    if (f.frames_with_bit == 0) continue;
    const std::string name = bit < fw::kHeadFaultBits ? std::string(fw::head_fault_name(bit)) : "bit" + std::to_string(bit);
    faults[name] = {{"frames", f.frames_with_bit}, {"raised", f.raised}, {"first_t_s", f.first_t_s}};
  }
  j["head_faults"] = faults;

  json hbs = json::object();
  for (const auto& [node, hb] : a.heartbeats())
    hbs[std::to_string(node)] = {{"count", hb.count},
                                 {"state", std::string(fw::to_string(static_cast<fw::NodeState>(hb.last_state)))},
                                 {"firmware", hb.firmware},
                                 {"protocol_version", hb.protocol_version},
                                 {"protocol_mismatches", hb.protocol_mismatches},
                                 {"uptime_s", hb.last_uptime_s}};
  j["heartbeats"] = hbs;

  const DroneCanStats& d = a.dronecan();
  if (d.frames > 0) {
    json e = timing_json(d.timing, 0);
    e.erase("bus_load");
    e["frames"] = d.frames;
    e["transfers"] = d.transfers;
    e["errors"] = d.errors;
    e["error_reasons"] = d.error_reasons;
    e["timed_out"] = d.timed_out;
    json nodes = json::object();
    for (const auto& [node, n] : d.per_node) nodes[std::to_string(node)] = n;
    e["per_node"] = nodes;
    j["dronecan_raw_imu"] = e;
  }
  j["imu_samples"] = a.imu_samples();
  return j;
}

std::string report_text(const ReadSummary& read, const LogAnalyzer& a) {
  std::string out;
  char line[512];
  const auto add = [&](const char* fmt_s, auto... args) {
    std::snprintf(line, sizeof line, fmt_s, args...);
    out += line;
  };
  const double span = span_s(a);
  add("log              %s\n", read.path.c_str());
  add("lines            %llu (%llu malformed, skipped)\n", static_cast<unsigned long long>(read.lines),
      static_cast<unsigned long long>(read.malformed));
  for (const auto& e : read.first_errors) add("  %s\n", e.c_str());
  add("frames           %llu (ours %llu, DroneCAN RawIMU %llu, other %llu in %llu unknown ids, error frames %llu)\n",
      static_cast<unsigned long long>(a.frames()), static_cast<unsigned long long>(a.protocol_frames()),
      static_cast<unsigned long long>(a.dronecan().frames), static_cast<unsigned long long>(a.unknown_frames()),
      static_cast<unsigned long long>(a.unknown_ids()), static_cast<unsigned long long>(a.error_frames()));
  if (a.timed())
    add("duration         %.6f s%s\n", span, a.frames_without_stamp() ? " (some lines without timestamps)" : "");
  else
    add("duration         - (no timestamps: rates, gaps and bus load cannot be computed)\n");
  add("bus load         %s %% at %.0f bit/s (classic frames bit-exact with stuffing)\n",
      fmt(100 * a.bus_load(), "%.2f").c_str(), a.options().bitrate);

  add("\nper id            count    rate_hz  gap_us p50/p99/max     jitter_us p50/p99/max  load_%%  message\n");
  for (const IdStats* s : a.ids()) {
    const auto ours = s->extended ? std::nullopt : fw::classify_id(s->id);
    add("%-12s %10llu %10s  %-22s %-22s %6s  %s\n", hex_id(s->id, s->extended).c_str(),
        static_cast<unsigned long long>(s->timing.count()), fmt(s->timing.timed() ? s->timing.rate_hz() : NAN).c_str(),
        gap_text(s->timing.gaps_us()).c_str(), gap_text(s->timing.jitter_us()).c_str(),
        fmt(span > 0 ? 100 * s->timing.bus_s() / span : NAN, "%.2f").c_str(),
        ours ? std::string(fw::to_string(ours->type)).c_str() : "");
  }
  bool any = false;
  for (int t = 0; t < fw::kMessageTypeCount; ++t) {
    const auto type = static_cast<fw::MessageType>(t);
    const MessageStats& m = a.message(type);
    if (m.timing.count() == 0) continue;
    if (!any) add("\nper message       count    decoded  rate_hz  lost  dup  out_of_range  other_errors  saturated\n");
    any = true;
    std::uint64_t other = 0;
    for (int k = 0; k < kWireErrorKinds; ++k)
      if (k != static_cast<int>(fw::WireErrorKind::OutOfRange)) other += m.errors[static_cast<std::size_t>(k)];
    add("%-15s %8llu %10llu %8s %5llu %4llu %13llu %13llu %10llu\n", std::string(fw::to_string(type)).c_str(),
        static_cast<unsigned long long>(m.timing.count()), static_cast<unsigned long long>(m.decoded),
        fmt(m.timing.timed() ? m.timing.rate_hz() : NAN).c_str(), static_cast<unsigned long long>(m.counter.lost()),
        static_cast<unsigned long long>(m.counter.duplicates()),
        static_cast<unsigned long long>(m.errors[static_cast<std::size_t>(fw::WireErrorKind::OutOfRange)]),
        static_cast<unsigned long long>(other), static_cast<unsigned long long>(m.saturated_frames));
  }
  if (!any) add("\nno frame of the epichead protocol in this log\n");
  for (int bit = 0; bit < 16; ++bit) {
    const FaultInfo& f = a.faults()[static_cast<std::size_t>(bit)];
    if (f.frames_with_bit)
      add("fault %-18s in %llu frames, raised %llu times, first at %.3f s\n",
          bit < fw::kHeadFaultBits ? std::string(fw::head_fault_name(bit)).c_str() : "reserved",
          static_cast<unsigned long long>(f.frames_with_bit), static_cast<unsigned long long>(f.raised), f.first_t_s);
  }
  for (const auto& [node, hb] : a.heartbeats())
    add("node %d: %llu heartbeats, %s, firmware %s, protocol %d%s\n", node, static_cast<unsigned long long>(hb.count),
        std::string(fw::to_string(static_cast<fw::NodeState>(hb.last_state))).c_str(), hb.firmware.c_str(),
        hb.protocol_version, hb.protocol_mismatches ? " (not ours!)" : "");
  const DroneCanStats& d = a.dronecan();
  if (d.frames)
    add("DroneCAN RawIMU: %llu frames, %llu transfers, %llu errors, %llu timed out\n",
        static_cast<unsigned long long>(d.frames), static_cast<unsigned long long>(d.transfers),
        static_cast<unsigned long long>(d.errors), static_cast<unsigned long long>(d.timed_out));
  add("IMU samples      %llu\n", static_cast<unsigned long long>(a.imu_samples()));
  return out;
}

}  // namespace epichead::tools::replay
