#pragma once
// The columns a document describes for a CSV: the `backticked` names in the first cell of each
// row of the first Markdown table after the line that starts with `marker` (README.md's "Files
// and conventions"), in order. Tests compare them with the header the program writes.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace epichead::testing {

inline std::vector<std::string> documented_columns(const std::string& markdown_path, const std::string& marker) {
  std::ifstream in(markdown_path);
  std::vector<std::string> names;
  bool found = false, in_table = false;
  for (std::string line; std::getline(in, line);) {
    if (!found) {
      found = line.starts_with(marker);
      continue;
    }
    if (!line.starts_with("|")) {
      if (in_table) break;
      continue;
    }
    in_table = true;
    const std::size_t end = line.find('|', 1);
    const std::string cell = line.substr(1, end == std::string::npos ? std::string::npos : end - 1);
    for (std::size_t open = cell.find('`'); open != std::string::npos; open = cell.find('`', open)) {
      const std::size_t close = cell.find('`', open + 1);
      if (close == std::string::npos) break;
      names.push_back(cell.substr(open + 1, close - open - 1));
      open = close + 1;
    }
  }
  return names;
}

// Names joined with commas, as a CSV header line.
inline std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& n : names) text += (text.empty() ? "" : ",") + n;
  return text;
}

}  // namespace epichead::testing
