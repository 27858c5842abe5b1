#pragma once
// What `epichead replay --dbc FILE` learns about the frames a DBC describes (devices that are
// not ours as much as our own): per message its count, rate and gaps against the DBC's
// GenMsgCycleTime, frames too short for a signal; per signal its count, rate, range seen and
// values outside the DBC's [min|max]; series of the chosen signals for a plot; and every
// decoded value to a sink (the --csv writer). Memory is bounded by the DBCs' size, not the log's.
#include <cstdint>
#include <expected>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "epichead/firmware_iface/candump_line.h"
#include "epichead/firmware_iface/dbc.h"
#include "epichead/firmware_iface/dbc_decode.h"
#include "replay/bounded_series.h"
#include "replay/stream_stats.h"

namespace epichead::tools::replay {

struct SignalStats {
  std::uint64_t count = 0;
  double min = std::numeric_limits<double>::quiet_NaN();  // physical values seen (finite ones)
  double max = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t not_finite = 0;    // float signals holding NaN or infinity
  std::uint64_t out_of_range = 0;  // outside the DBC's [min|max] (when it states one)
  double first_out_of_range_t_s = std::numeric_limits<double>::quiet_NaN();
  double first_out_of_range_value = std::numeric_limits<double>::quiet_NaN();
  std::int64_t first_us = 0, last_us = 0;
  std::uint64_t timed = 0;         // values with a log time stamp
  double rate_hz() const;          // (timed - 1) / span; NaN under two stamped values
};

// How a message's measured period compares with its GenMsgCycleTime: the median gap within
// kCycleTolerance of it, or off it either way.
enum class CycleCheck { NotStated, NotMeasured, Ok, Slower, Faster };
inline constexpr double kCycleTolerance = 0.10;
// A gap over this many cycle times is a late (or lost) frame.
inline constexpr double kLateGapCycles = 1.5;
std::string_view to_string(CycleCheck c);

struct DbcMessageStats {
  const firmware_iface::DbcMessage* message = nullptr;
  std::string dbc;                  // the file it is from
  StreamStats timing;
  std::uint64_t too_short = 0;      // frames too short for one of the signals they carry
  std::uint64_t other_length = 0;   // frames whose length is not the DBC's
  std::uint64_t unknown_multiplexer = 0;  // frames whose multiplexor value selects no signal
  std::uint64_t late_gaps = 0;      // gaps over kLateGapCycles cycle times (with a cycle time)
  std::vector<SignalStats> signals;  // as message->signals

  CycleCheck cycle_check() const;
  double median_period_ms() const;  // NaN without gaps
};

// One decoded value, as the --csv sink sees it.
struct DecodedSignal {
  const firmware_iface::CandumpRecord* record;
  const firmware_iface::DbcMessage* message;
  const firmware_iface::DbcSignal* signal;
  const firmware_iface::DbcValue* value;
};

class DbcAnalyzer {
 public:
  // The databases in the order given; an id defined in two of them is an error (which file
  // would decode it?), as is a chosen signal ("MESSAGE.SIGNAL") that none has.
  static std::expected<DbcAnalyzer, std::string> create(std::vector<firmware_iface::Dbc> dbcs,
                                                        const std::vector<std::string>& plotted = {});

  void add(const firmware_iface::CandumpRecord& record);
  // Called with every decoded value in log order (optional).
  void on_value(std::function<void(const DecodedSignal&)> sink) { sink_ = std::move(sink); }

  const std::vector<firmware_iface::Dbc>& dbcs() const { return dbcs_; }
  // Per message of the databases, in their order (messages never seen have count 0).
  const std::vector<DbcMessageStats>& messages() const { return stats_; }
  std::uint64_t decoded_frames() const { return decoded_frames_; }
  std::uint64_t other_frames() const { return other_frames_; }  // frames of ids no DBC has

  struct Plotted {
    std::string name;  // MESSAGE.SIGNAL
    std::string unit;
    BoundedSeries<1> series;  // log time, physical value
  };
  const std::vector<Plotted>& plotted() const { return plotted_; }

 private:
  DbcAnalyzer() = default;
  std::vector<firmware_iface::Dbc> dbcs_;
  std::vector<DbcMessageStats> stats_;
  std::map<std::uint64_t, std::size_t> by_id_;  // id | extended << 32 -> stats_ index
  std::vector<std::vector<int>> plot_slot_;     // per stats_ index, per signal: plotted_ index or -1
  std::vector<Plotted> plotted_;
  std::vector<firmware_iface::DbcValue> scratch_;  // one frame's values, sized once
  std::function<void(const DecodedSignal&)> sink_;
  std::uint64_t decoded_frames_ = 0, other_frames_ = 0;
};

}  // namespace epichead::tools::replay
