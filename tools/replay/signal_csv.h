#pragma once
// The --csv file of `epichead replay --dbc`: one row per decoded signal value, in log order.
// The long form suits multiplexed messages (a row per frame would be mostly empty) and is what
// pandas (df.pivot_table(index="t_s", columns="signal", values="value")) and Excel's pivot
// tables take. Columns:
//   t_s      log time in seconds as in the log (sec.usec; empty for a line without one)
//   id       CAN id in hex (0x123, 29-bit as 0x1F334455)
//   message  DBC message name         signal  DBC signal name
//   raw      the raw integer (or the IEEE value of a float signal)
//   value    physical value, raw * factor + offset
//   unit     DBC unit                 text    the VAL_ text of the raw value, empty if none
// Text fields are quoted when they hold a comma or a quote (RFC 4180).
#include <cstdio>
#include <expected>
#include <memory>
#include <string>

#include "replay/dbc_analysis.h"

namespace epichead::tools::replay {

class SignalCsv {
 public:
  // Creates the file and writes the header; the error names the path.
  static std::expected<SignalCsv, std::string> open(const std::string& path);
  void write(const DecodedSignal& d);
  // Flushes and closes; the error names the path (a full disk shows here).
  std::expected<void, std::string> close();
  std::uint64_t rows() const { return rows_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::string path_;
  std::unique_ptr<std::FILE, Closer> file_;
  std::uint64_t rows_ = 0;
};

}  // namespace epichead::tools::replay
