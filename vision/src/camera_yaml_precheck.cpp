#include "camera_yaml_precheck.h"

namespace epichead::vision {
namespace {

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// True when the ':' at `colon` of `line` is a mapping indicator with nothing before it: at the
// start of the line (after blanks or a "- " / "? " indicator), after '{' or ',' in a flow
// collection, or after an empty quoted scalar ("" or '').
bool empty_key_before(std::string_view line, std::size_t colon) {
  std::size_t i = colon;
  while (i > 0 && is_blank(line[i - 1])) --i;
  if (i == 0) return true;
  const char prev = line[i - 1];
  if (prev == '{' || prev == ',') return true;
  if ((prev == '-' || prev == '?') && (i == 1 || is_blank(line[i - 2]))) return true;
  if ((prev == '"' || prev == '\'') && i >= 2 && line[i - 2] == prev) {
    // An empty quoted scalar, unless it is the end of an escaped quote inside a longer one.
    const std::size_t before = i - 2;
    return before == 0 || is_blank(line[before - 1]) || line[before - 1] == '{' || line[before - 1] == ',';
  }
  return false;
}

}  // namespace

std::expected<void, std::string> precheck_camera_yaml(std::string_view text) {
  if (text.size() > kCameraYamlMaxBytes)
    return std::unexpected("file is larger than " + std::to_string(kCameraYamlMaxBytes >> 20) +
                           " MiB, which no camera calibration is");
  if (text.find('\0') != std::string_view::npos) return std::unexpected(std::string("binary data (a NUL byte), not YAML text"));
  std::size_t line_no = 0;
  for (std::size_t start = 0; start < text.size();) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(start, end - start);
    ++line_no;
    start = end + 1;
    if (line.starts_with('%')) continue;  // a directive: "%YAML:1.0"
    char quote = '\0';
    for (std::size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (quote) {
        if (quote == '"' && c == '\\') ++i;  // an escape in a double-quoted scalar
        else if (c == quote) quote = '\0';
        continue;
      }
      if (c == '#' && (i == 0 || is_blank(line[i - 1]))) break;  // a comment
      if (c == '"' || c == '\'') {
        if (i + 1 < line.size() && line[i + 1] == c) {  // an empty quoted scalar: a ':' after it is checked
          ++i;
          continue;
        }
        quote = c;
        continue;
      }
      if (c == ':' && empty_key_before(line, i))
        return std::unexpected("line " + std::to_string(line_no) + ": empty key before ':'");
    }
  }
  return {};
}

}  // namespace epichead::vision
