#include "csv_rows.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace epichead::vision::csv {
namespace {

using Error = std::unexpected<std::string>;

std::string_view trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string> split(std::string_view line) {
  std::vector<std::string> fields;
  for (;;) {
    const std::size_t comma = line.find(',');
    fields.emplace_back(trim(line.substr(0, comma)));
    if (comma == std::string_view::npos) break;
    line.remove_prefix(comma + 1);
  }
  return fields;
}

std::string join(const std::vector<std::string_view>& columns) {
  std::string s;
  for (const auto& c : columns) {
    if (!s.empty()) s += ',';
    s += c;
  }
  return s;
}

}  // namespace

std::expected<Table, std::string> read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error(path + ": cannot open");
  Table table;
  table.path = path;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::string_view view(line);
    if (number == 1 && view.starts_with("\xEF\xBB\xBF")) view.remove_prefix(3);  // UTF-8 BOM
    if (view.find('\0') != std::string_view::npos) return Error(path + ":" + std::to_string(number) + ": binary data (NUL byte)");
    if (trim(view).empty()) continue;
    if (table.header_line == 0) {
      table.header_line = number;
      table.header = split(view);
    } else {
      table.rows.push_back({number, split(view)});
    }
  }
  if (in.bad()) return Error(path + ": read error");
  if (table.header_line == 0) return Error(path + ": empty (no header line)");
  return table;
}

std::expected<bool, std::string> check_header(const Table& table, const std::vector<std::string_view>& columns,
                                              std::optional<std::string_view> optional_last) {
  const auto prefix_matches = [&] {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (table.header[i] != columns[i]) return false;
    return true;
  };
  if (table.header.size() == columns.size() && prefix_matches()) return false;
  if (optional_last && table.header.size() == columns.size() + 1 && prefix_matches() &&
      table.header.back() == *optional_last)
    return true;
  std::string got;
  for (const auto& h : table.header) got += (got.empty() ? "" : ",") + h;
  return Error(table.path + ":" + std::to_string(table.header_line) + ": header must be '" + join(columns) + "'" +
               (optional_last ? std::string(" (optionally followed by ',") + std::string(*optional_last) + "')" : std::string()) +
               ", got '" + got + "'");
}

std::string where(const Table& table, const Row& row) { return table.path + ":" + std::to_string(row.line) + ": "; }

std::optional<double> parse_finite(std::string_view text) {
  if (text.starts_with('+')) text.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<int> parse_int(std::string_view text) {
  if (text.starts_with('+')) text.remove_prefix(1);
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::string number_problem(std::string_view column, std::string_view text) {
  std::string_view t = text.starts_with('+') ? text.substr(1) : text;
  double value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (!t.empty() && ec == std::errc() && end == t.data() + t.size() && !std::isfinite(value))
    return std::string(column) + " is not finite ('" + std::string(text) + "')";
  if (text.empty()) return std::string(column) + " is empty";
  return std::string(column) + " is not a number ('" + std::string(text) + "')";
}

void append_exact(std::string& out, double value) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value);
  out.append(buf, ec == std::errc() ? end : buf);
}

void append_9g(std::string& out, double value) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, "%.9g", value);
  if (n > 0) out.append(buf, static_cast<std::size_t>(n));
}

std::expected<void, std::string> write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Error(path + ": cannot open for writing");
  out << text;
  out.close();
  if (!out) return Error(path + ": write error");
  return {};
}

}  // namespace epichead::vision::csv
