#pragma once
// `epichead score --per-frame` output (frame,present,success,rotation_deg,...) read back by the
// tools' tests: whether each scored frame was within the success bounds.
#include <fstream>
#include <map>
#include <string>

namespace epichead::testing {

// Frame -> success, for every row of the file (empty when it cannot be read).
inline std::map<int, bool> frame_successes(const std::string& per_frame_csv) {
  std::map<int, bool> out;
  std::ifstream in(per_frame_csv);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    const auto first = line.find(','), second = line.find(',', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    out[std::stoi(line)] = line.compare(second + 1, 2, "1,") == 0;
  }
  return out;
}

}  // namespace epichead::testing
