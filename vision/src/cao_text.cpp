#include "cao_text.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

namespace epichead::vision::cao_text {
namespace {

namespace fs = std::filesystem;

constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

}  // namespace

std::expected<std::string, std::string> read_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return std::unexpected(path.string() + ": cannot open (no such file)");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec || size > kMaxFileBytes) return std::unexpected(path.string() + ": cannot read (unreadable or too large)");
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::unexpected(path.string() + ": cannot open");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return std::unexpected(path.string() + ": read error");
  return std::move(buffer).str();
}

Lexer::Lexer(std::string_view text) : text_(text) {
  if (text_.starts_with("\xEF\xBB\xBF")) pos_ = 3;  // UTF-8 byte order mark
}

Token Lexer::next() {
  skip_blank();
  if (pos_ >= text_.size()) {
    // The end is on the last line, not on the empty one after a final line break.
    const bool final_break = !text_.empty() && text_.back() == '\n';
    return {{}, std::max(1, line_ - (final_break ? 1 : 0))};
  }
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_space(text_[pos_]) && text_[pos_] != '#') {
    if (text_[pos_] == '"' && pos_ > start && text_[pos_ - 1] == '=') {
      // name="a b": a quoted attribute value may hold blanks, not a line break.
      const std::size_t close = text_.find_first_of("\"\n", pos_ + 1);
      pos_ = close == std::string_view::npos ? text_.size() : (text_[close] == '"' ? close + 1 : close);
      continue;
    }
    ++pos_;
  }
  return {text_.substr(start, pos_ - start), line_};
}

Token Lexer::peek() {
  const std::size_t pos = pos_;
  const int line = line_;
  const Token t = next();
  pos_ = pos;
  line_ = line;
  return t;
}

std::string_view Lexer::take_line(const Token& t) {
  const auto start = static_cast<std::size_t>(t.text.data() - text_.data());
  std::size_t end = text_.find('\n', start);
  if (end == std::string_view::npos) end = text_.size();
  pos_ = end;
  line_ = t.line;
  return text_.substr(start, end - start);
}

void Lexer::skip_blank() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (is_space(c)) {
      line_ += c == '\n';
      ++pos_;
    } else if (c == '#' || (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/')) {
      const std::size_t eol = text_.find('\n', pos_);
      pos_ = eol == std::string_view::npos ? text_.size() : eol;
    } else {
      break;
    }
  }
}

std::string shown(const Token& t) {
  if (t.end()) return "end of file";
  std::string out = "'";
  const std::size_t n = std::min<std::size_t>(t.text.size(), 40);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(t.text[i]);
    if (c < 0x20 || c >= 0x7f) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (t.text.size() > n) out += "...";
  return out + "'";
}

bool parse_integer(std::string_view s, long long& value, bool& overflow) {
  overflow = false;
  if (s.starts_with('+')) s.remove_prefix(1);
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (end != s.data() + s.size()) return false;
  if (ec == std::errc::result_out_of_range) overflow = true;
  return ec == std::errc{} || overflow;
}

bool parse_number(std::string_view s, double& value) {
  if (s.starts_with('+')) s.remove_prefix(1);
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  return ec == std::errc{} && end == s.data() + s.size() && std::isfinite(value);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

}  // namespace epichead::vision::cao_text
