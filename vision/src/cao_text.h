#pragma once
// Private to the CAO reader: a CAO file's text, its tokens, each with its line for messages, and the
// number parsing the reader shares. ViSP reads a CAO file as a stream of whitespace-separated
// tokens, so tokens may be spread over lines freely.
#include <expected>
#include <filesystem>
#include <string>
#include <string_view>

namespace epichead::vision::cao_text {

// The whole of a file (at most 1 GiB: no model is larger), or "path: what went wrong".
std::expected<std::string, std::string> read_file(const std::filesystem::path& path);

struct Token {
  std::string_view text;  // empty at the end of the input
  int line = 0;
  bool end() const { return text.empty(); }
};

// Splits CAO text into tokens, dropping `#` and `//` comments (ViSP's documentation writes `//`
// after values) and a UTF-8 byte order mark, counting lines. The text must outlive the lexer.
class Lexer {
 public:
  explicit Lexer(std::string_view text);
  Token next();
  Token peek();  // the next token, not consumed
  // The rest of the line from the start of `t` (a token from peek()), consumed.
  std::string_view take_line(const Token& t);
  int line() const { return line_; }

 private:
  void skip_blank();
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

// A token as it appears in a message: quoted, shortened, control bytes escaped.
std::string shown(const Token& t);
// A whole number taking all of `s` (a leading '+' allowed); overflow is set, and true returned,
// when it is one but does not fit.
bool parse_integer(std::string_view s, long long& value, bool& overflow);
// A finite decimal number taking the whole of `s`.
bool parse_number(std::string_view s, double& value);
// `s` without leading and trailing blanks.
std::string_view trim(std::string_view s);

}  // namespace epichead::vision::cao_text
