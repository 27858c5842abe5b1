#pragma once
// The replay report's section on the signals of the DBC files (--dbc): a JSON object and text.
#include <nlohmann/json.hpp>

#include <string>

#include "replay/dbc_analysis.h"

namespace epichead::tools::replay {

// {"files", "decoded_frames", "other_frames", "messages": [...seen in the log...],
//  "messages_not_seen": [names]}; each message with its timing, cycle-time check and
// "signals": {name: {count, rate_hz, min, max, unit, dbc_min, dbc_max, out_of_range, ...}}.
nlohmann::json dbc_report_json(const DbcAnalyzer& a);
std::string dbc_report_text(const DbcAnalyzer& a);

}  // namespace epichead::tools::replay
