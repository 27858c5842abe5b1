#include "replay/dbc_report.h"
#include "report_format.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace epichead::tools::replay {

namespace fw = firmware_iface;
using nlohmann::json;

namespace {

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string fmt(double v, const char* f = "%.6g") { return format_number(v, f); }

std::string range_text(const fw::DbcSignal& s) {
  if (!s.has_range()) return "-";
  std::string out(1, '[');  // appended, not "[" + ...: GCC 12 warns falsely (-Wrestrict) on that
  out += fmt(s.min);
  out += '|';
  out += fmt(s.max);
  out += ']';
  return out;
}

std::size_t signal_count(const fw::Dbc& d) {
  std::size_t n = 0;
  for (const auto& m : d.messages) n += m.signals.size();
  return n;
}

json signal_json(const fw::DbcSignal& sig, const SignalStats& s) {
  json j{{"count", s.count}, {"rate_hz", number(s.rate_hz())}, {"min", number(s.min)}, {"max", number(s.max)},
         {"unit", sig.unit}};
  j["dbc_min"] = sig.has_range() ? json(sig.min) : json(nullptr);
  j["dbc_max"] = sig.has_range() ? json(sig.max) : json(nullptr);
  j["out_of_range"] = s.out_of_range;
  if (s.out_of_range > 0) {
    j["first_out_of_range_t_s"] = number(s.first_out_of_range_t_s);
    j["first_out_of_range_value"] = number(s.first_out_of_range_value);
  }
  if (s.not_finite > 0) j["not_finite"] = s.not_finite;
  if (sig.multiplexing == fw::Multiplexing::Multiplexor) j["multiplexor"] = true;
  if (sig.multiplexing == fw::Multiplexing::Multiplexed) j["multiplexer_value"] = sig.multiplexer_value;
  return j;
}

}  // namespace

json dbc_report_json(const DbcAnalyzer& a) {
  json j;
  json files = json::array();
  for (const auto& d : a.dbcs())
    files.push_back({{"path", d.path}, {"messages", d.messages.size()}, {"signals", signal_count(d)}, {"warnings", d.warnings}});
  j["files"] = files;
  j["decoded_frames"] = a.decoded_frames();
  j["other_frames"] = a.other_frames();
  json messages = json::array(), not_seen = json::array();
  for (const DbcMessageStats& ms : a.messages()) {
    const fw::DbcMessage& m = *ms.message;
    if (ms.timing.count() == 0) {
      not_seen.push_back(m.name);
      continue;
    }
    json e{{"message", m.name}, {"id", hex_id(m.id, m.extended)}, {"extended", m.extended},
           {"dbc", std::filesystem::path(ms.dbc).filename().string()}, {"count", ms.timing.count()}};
    e["rate_hz"] = ms.timing.timed() ? json(ms.timing.rate_hz()) : json(nullptr);
    e["cycle_time_ms"] = m.cycle_time_ms ? json(*m.cycle_time_ms) : json(nullptr);
    e["median_period_ms"] = number(ms.median_period_ms());
    e["max_period_ms"] = ms.timing.gaps_us().count() ? json(ms.timing.gaps_us().max() * 1e-3) : json(nullptr);
    e["cycle_check"] = std::string(to_string(ms.cycle_check()));
    if (m.cycle_time_ms) e["late_gaps"] = ms.late_gaps;
    e["too_short"] = ms.too_short;
    e["other_length"] = ms.other_length;
    if (m.multiplexor >= 0) e["unknown_multiplexer"] = ms.unknown_multiplexer;
    json signals = json::object();
    for (std::size_t i = 0; i < m.signals.size(); ++i) signals[m.signals[i].name] = signal_json(m.signals[i], ms.signals[i]);
    e["signals"] = signals;
    messages.push_back(e);
  }
  j["messages"] = messages;
  j["messages_not_seen"] = not_seen;
  return j;
}

std::string dbc_report_text(const DbcAnalyzer& a) {
  std::string out;
  char line[512];
  const auto add = [&](const char* fmt_s, auto... args) {
    std::snprintf(line, sizeof line, fmt_s, args...);
    out += line;
  };
  for (const auto& d : a.dbcs()) {
    add("\nDBC %s: %zu messages, %zu signals\n", d.path.c_str(), d.messages.size(), signal_count(d));
    for (const auto& w : d.warnings) out += "  warning: " + w + "\n";
  }
  std::size_t ids = 0;
  for (const auto& ms : a.messages()) ids += ms.timing.count() > 0;
  add("frames decoded   %llu in %zu ids (%llu frames of ids no DBC has)\n",
      static_cast<unsigned long long>(a.decoded_frames()), ids, static_cast<unsigned long long>(a.other_frames()));
  std::string not_seen;
  for (const DbcMessageStats& ms : a.messages()) {
    const fw::DbcMessage& m = *ms.message;
    if (ms.timing.count() == 0) {
      not_seen += (not_seen.empty() ? "" : ", ") + m.name;
      continue;
    }
    add("\n%s %s: %llu frames, %s Hz", m.name.c_str(), hex_id(m.id, m.extended).c_str(),
        static_cast<unsigned long long>(ms.timing.count()), fmt(ms.timing.timed() ? ms.timing.rate_hz() : NAN, "%.2f").c_str());
    if (m.cycle_time_ms)
      add(", cycle %d ms, median period %s ms: %s, %llu gaps over %.1f cycles", *m.cycle_time_ms,
          fmt(ms.median_period_ms(), "%.3f").c_str(), std::string(to_string(ms.cycle_check())).c_str(),
          static_cast<unsigned long long>(ms.late_gaps), kLateGapCycles);
    else
      add(", median period %s ms (no GenMsgCycleTime)", fmt(ms.median_period_ms(), "%.3f").c_str());
    add("\n");
    if (ms.too_short || ms.other_length)
      add("  %llu frames too short for a signal, %llu not %d bytes long\n", static_cast<unsigned long long>(ms.too_short),
          static_cast<unsigned long long>(ms.other_length), m.length);
    if (ms.unknown_multiplexer)
      add("  %llu frames whose multiplexor value selects no signal\n", static_cast<unsigned long long>(ms.unknown_multiplexer));
    if (m.signals.empty()) {
      out += "  (the DBC gives it no signals)\n";
      continue;
    }
    add("  %-36s %8s %8s %12s %12s %-10s %-22s %s\n", "signal", "count", "rate_hz", "min", "max", "unit", "dbc range",
        "out_of_range");
    for (std::size_t i = 0; i < m.signals.size(); ++i) {
      const fw::DbcSignal& sig = m.signals[i];
      const SignalStats& s = ms.signals[i];
      std::string name = sig.name;
      if (sig.multiplexing == fw::Multiplexing::Multiplexor) name += " (M)";
      if (sig.multiplexing == fw::Multiplexing::Multiplexed) name += " (m" + std::to_string(sig.multiplexer_value) + ")";
      std::string bad = std::to_string(s.out_of_range);
      if (s.out_of_range) bad += " (first " + fmt(s.first_out_of_range_value) + " at " + fmt(s.first_out_of_range_t_s, "%.6f") + " s)";
      if (s.not_finite) bad += ", " + std::to_string(s.not_finite) + " not finite";
      add("  %-36s %8llu %8s %12s %12s %-10s %-22s %s\n", name.c_str(), static_cast<unsigned long long>(s.count),
          fmt(s.rate_hz(), "%.2f").c_str(), fmt(s.min).c_str(), fmt(s.max).c_str(), sig.unit.c_str(),
          range_text(sig).c_str(), bad.c_str());
    }
  }
  if (!not_seen.empty()) out += "\nnot in the log: " + not_seen + "\n";
  return out;
}

}  // namespace epichead::tools::replay
