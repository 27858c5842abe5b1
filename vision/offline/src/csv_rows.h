#pragma once
// Private helpers for the project's small CSV tables (pose, IMU and frame lists): a header line
// naming the columns, then rows of comma-separated fields. Tolerates CRLF, a UTF-8 BOM, blank
// lines and spaces around fields; no quoting (no field holds a comma).
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace epichead::vision::csv {

struct Row {
  int line = 0;                     // 1-based line number in the file
  std::vector<std::string> fields;  // trimmed
};

struct Table {
  std::string path;
  int header_line = 0;
  std::vector<std::string> header;  // trimmed column names
  std::vector<Row> rows;
};

// Reads the whole file; the first non-blank line is the header. Errors: cannot open, empty file.
std::expected<Table, std::string> read(const std::string& path);

// Checks that the header is exactly `columns`, or `columns` followed by `optional_last`
// (when given). Returns whether the optional column is present.
std::expected<bool, std::string> check_header(const Table& table, const std::vector<std::string_view>& columns,
                                              std::optional<std::string_view> optional_last = std::nullopt);

// "path:line: " for messages about a row.
std::string where(const Table& table, const Row& row);

// A finite floating-point number, or nullopt.
std::optional<double> parse_finite(std::string_view text);
// A whole number that fits an int, or nullopt.
std::optional<int> parse_int(std::string_view text);

// Error text for a field that should be a finite number ("not a number" / "not finite").
std::string number_problem(std::string_view column, std::string_view text);

// Appends the shortest text that reads back as exactly `value`.
void append_exact(std::string& out, double value);
// Appends `value` with 9 significant digits (poses: nm and 1e-9 rad are plenty).
void append_9g(std::string& out, double value);

// Writes `text` to `path` (replacing it); errors name the file.
std::expected<void, std::string> write_file(const std::string& path, const std::string& text);

}  // namespace epichead::vision::csv
