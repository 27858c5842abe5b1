#include "replay/dbc_analysis.h"
#include "report_format.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace epichead::tools::replay {

namespace fw = firmware_iface;

namespace {

std::uint64_t key_of(std::uint32_t id, bool extended) { return id | (std::uint64_t{extended} << 32); }

// "MESSAGE.SIGNAL" split at its first dot.
std::pair<std::string_view, std::string_view> split_name(std::string_view full) {
  const auto dot = full.find('.');
  if (dot == std::string_view::npos) return {full, {}};
  return {full.substr(0, dot), full.substr(dot + 1)};
}

}  // namespace

double SignalStats::rate_hz() const {
  if (timed < 2 || last_us <= first_us) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(timed - 1) / ((last_us - first_us) * 1e-6);
}

std::string_view to_string(CycleCheck c) {
  switch (c) {
    case CycleCheck::NotStated: return "not stated";
    case CycleCheck::NotMeasured: return "not measured";
    case CycleCheck::Ok: return "ok";
    case CycleCheck::Slower: return "slower";
    case CycleCheck::Faster: return "faster";
  }
  return "?";
}

double DbcMessageStats::median_period_ms() const {
  return timing.gaps_us().count() > 0 ? timing.gaps_us().percentile(0.5) * 1e-3 : std::numeric_limits<double>::quiet_NaN();
}

CycleCheck DbcMessageStats::cycle_check() const {
  if (!message->cycle_time_ms) return CycleCheck::NotStated;
  const double measured = median_period_ms();
  if (!std::isfinite(measured)) return CycleCheck::NotMeasured;
  const double cycle = *message->cycle_time_ms;
  if (measured > cycle * (1 + kCycleTolerance)) return CycleCheck::Slower;
  if (measured < cycle * (1 - kCycleTolerance)) return CycleCheck::Faster;
  return CycleCheck::Ok;
}

std::expected<DbcAnalyzer, std::string> DbcAnalyzer::create(std::vector<fw::Dbc> dbcs,
                                                            const std::vector<std::string>& plotted) {
  DbcAnalyzer a;
  a.dbcs_ = std::move(dbcs);
  std::size_t most_signals = 0;
  for (const fw::Dbc& dbc : a.dbcs_) {
    for (const fw::DbcMessage& m : dbc.messages) {
      const auto [it, fresh] = a.by_id_.emplace(key_of(m.id, m.extended), a.stats_.size());
      if (!fresh) {
        const DbcMessageStats& other = a.stats_[it->second];
        return std::unexpected("--dbc: id " + hex_id(m.id, m.extended) + " is " + m.name + " in " + dbc.path +
                               " and " + other.message->name + " in " + other.dbc);
      }
      DbcMessageStats s;
      s.message = &m;
      s.dbc = dbc.path;
      s.signals.resize(m.signals.size());
      a.stats_.push_back(std::move(s));
      a.plot_slot_.emplace_back(m.signals.size(), -1);
      most_signals = std::max(most_signals, m.signals.size());
    }
  }
  a.scratch_.resize(most_signals);
  for (const std::string& full : plotted) {
    const auto [message, signal] = split_name(full);
    const auto stats = std::find_if(a.stats_.begin(), a.stats_.end(),
                                    [&](const DbcMessageStats& s) { return s.message->name == message; });
    if (stats == a.stats_.end())
      return std::unexpected("--signal " + full + ": no message " + std::string(message) +
                             " in the DBC files (give MESSAGE.SIGNAL as the DBC names them)");
    const auto& sigs = stats->message->signals;
    const auto sig = std::find_if(sigs.begin(), sigs.end(), [&](const fw::DbcSignal& s) { return s.name == signal; });
    if (sig == sigs.end()) {
      std::string names;
      for (const auto& s : sigs) names += (names.empty() ? "" : ", ") + s.name;
      return std::unexpected("--signal " + full + ": " + std::string(message) + " has no signal '" +
                             std::string(signal) + "' (it has: " + (names.empty() ? "none" : names) + ")");
    }
    const auto m = static_cast<std::size_t>(stats - a.stats_.begin());
    const auto i = static_cast<std::size_t>(sig - sigs.begin());
    if (a.plot_slot_[m][i] >= 0) continue;  // named twice
    a.plot_slot_[m][i] = static_cast<int>(a.plotted_.size());
    a.plotted_.push_back({full, sig->unit, {}});
  }
  return a;
}

void DbcAnalyzer::add(const fw::CandumpRecord& r) {
  const fw::CanFrame& f = r.frame.frame;
  if (f.error() || f.remote()) {
    ++other_frames_;
    return;
  }
  const auto it = by_id_.find(key_of(f.id, f.extended()));
  if (it == by_id_.end()) {
    ++other_frames_;
    return;
  }
  ++decoded_frames_;
  DbcMessageStats& ms = stats_[it->second];
  const fw::DbcMessage& m = *ms.message;
  ms.timing.add(r.frame.stamp_us, r.has_stamp, 0);
  if (m.cycle_time_ms && r.has_stamp && ms.timing.last_gap_us() > kLateGapCycles * 1e3 * *m.cycle_time_ms) ++ms.late_gaps;
  if (f.len != m.length) ++ms.other_length;

  const fw::DbcFrameDecode d = fw::decode_frame(m, std::span(f.data.data(), f.len), scratch_);
  if (d.too_short > 0) ++ms.too_short;
  bool selected = m.multiplexor < 0 || !d.multiplexer;
  const double t_s = r.frame.stamp_us * 1e-6;
  for (std::size_t k = 0; k < d.values; ++k) {
    const fw::DbcValue& v = scratch_[k];
    const fw::DbcSignal& sig = m.signals[v.signal];
    selected |= sig.multiplexing == fw::Multiplexing::Multiplexed;
    SignalStats& s = ms.signals[v.signal];
    ++s.count;
    if (r.has_stamp) {
      if (s.timed++ == 0) s.first_us = r.frame.stamp_us;
      s.last_us = r.frame.stamp_us;
    }
    if (!std::isfinite(v.physical)) {
      ++s.not_finite;
    } else {
      s.min = std::isnan(s.min) ? v.physical : std::min(s.min, v.physical);
      s.max = std::isnan(s.max) ? v.physical : std::max(s.max, v.physical);
      // The range check allows for the decimal rounding of the DBC's stated limits.
      const double slack = 1e-9 * std::max(std::abs(sig.min), std::abs(sig.max));
      if (sig.has_range() && (v.physical < sig.min - slack || v.physical > sig.max + slack)) {
        if (s.out_of_range++ == 0) {
          s.first_out_of_range_t_s = t_s;
          s.first_out_of_range_value = v.physical;
        }
      }
    }
    const int slot = plot_slot_[it->second][v.signal];
    if (slot >= 0 && r.has_stamp) plotted_[static_cast<std::size_t>(slot)].series.add(t_s, {v.physical});
    if (sink_) sink_({&r, &m, &sig, &v});
  }
  if (!selected) ++ms.unknown_multiplexer;
}

}  // namespace epichead::tools::replay
