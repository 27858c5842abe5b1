// printable(): file names and text from files reach the terminal escaped, never as control
// sequences; and the program's error messages go through it.
#include <catch2/catch.hpp>

#include <string>

#include "common/run_tool.h"
#include "printable.h"

using epichead::tools::printable;

TEST_CASE("printable keeps ASCII and UTF-8 text and escapes control and non-UTF-8 bytes") {
  CHECK(printable("model.cao: line 3") == "model.cao: line 3");
  CHECK(printable("caméra\tß €") == "caméra\tß €");
  CHECK(printable("\x1b[31mred") == "\\x1B[31mred");
  CHECK(printable(std::string("a\0b\n\r\x7f", 6)) == "a\\x00b\\x0A\\x0D\\x7F");
  CHECK(printable("\xff\xfe") == "\\xFF\\xFE");
  CHECK(printable("\xc2\x9b" "2J") == "\\u009B2J");     // C1 CSI encoded as UTF-8
  CHECK(printable("\xc0\xaf") == "\\xC0\\xAF");          // overlong '/'
  CHECK(printable("\xed\xa0\x80") == "\\xED\\xA0\\x80");  // a surrogate
  CHECK(printable("\xe2\x82") == "\\xE2\\x82");          // cut short
}

TEST_CASE("A file name with an escape sequence reaches stderr escaped") {
  epichead::testing::TempDir scratch;
  const auto r = epichead::testing::run_epichead(
      scratch, "track " + epichead::testing::shell_quoted(scratch / "\x1b[31mred\x07") + " --out " +
                   epichead::testing::shell_quoted(scratch / "out"));
  CHECK(r.exit_code == 1);
  CHECK(r.err.find('\x1b') == std::string::npos);
  CHECK(r.err.find('\x07') == std::string::npos);
  CHECK(r.err.find("\\x1B[31mred\\x07") != std::string::npos);
}
