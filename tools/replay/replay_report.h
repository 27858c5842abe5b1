#pragma once
// The replay tool's outputs from a LogAnalyzer: a JSON object and a human-readable report.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "epichead/firmware_iface/candump_reader.h"
#include "replay/log_analysis.h"

namespace epichead::tools::replay {

struct ReadSummary {
  std::string path;
  std::uint64_t lines = 0, malformed = 0;
  std::vector<std::string> first_errors;  // "path:line:column: reason"
};

nlohmann::json report_json(const ReadSummary& read, const LogAnalyzer& a);
std::string report_text(const ReadSummary& read, const LogAnalyzer& a);

}  // namespace epichead::tools::replay
