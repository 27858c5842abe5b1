// Exit codes of `epichead`: 0 done, 1 a runtime error, 2 a command line that does not parse
// (with a one-line reason and the usage line); an unknown command is named.
#include <catch2/catch.hpp>

#include <string>

#include "common/run_tool.h"

using epichead::testing::run_epichead;
using epichead::testing::TempDir;

TEST_CASE("Help and version exit 0") {
  TempDir scratch;
  CHECK(run_epichead(scratch, "--help").exit_code == 0);
  CHECK(run_epichead(scratch, "track --help").exit_code == 0);
  CHECK(run_epichead(scratch, "--version").exit_code == 0);
}

TEST_CASE("An unknown command exits 2 and names itself") {
  TempDir scratch;
  const auto r = run_epichead(scratch, "foo");
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("epichead: unknown command 'foo'") && Catch::Contains("Usage: epichead") &&
                        Catch::Contains("track"));
}

TEST_CASE("Usage errors exit 2 with the reason and the command's usage line") {
  TempDir scratch;
  const struct {
    const char* args;
    const char* reason_part;
  } cases[] = {
      {"", "subcommand"},                                     // no command
      {"track", "required"},                                  // missing positional and option
      {"track seq --out o --every nope", "--every"},         // not a number
      {"track seq --out o --no-such-option", "--no-such-option"},
      {"score", "required"},
      {"--no-such-flag", "--no-such-flag"},
  };
  for (const auto& c : cases) {
    INFO(c.args);
    const auto r = run_epichead(scratch, c.args);
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.err, Catch::Contains(c.reason_part) && Catch::Contains("Usage: epichead"));
  }
  const auto track = run_epichead(scratch, "track");
  CHECK_THAT(track.err, Catch::StartsWith("epichead track: ") && Catch::Contains("Usage: epichead track"));
}

TEST_CASE("Runtime errors exit 1 with one line") {
  TempDir scratch;
  const auto r = run_epichead(scratch, "track " + epichead::testing::shell_quoted(scratch / "missing") + " --out " +
                                           epichead::testing::shell_quoted(scratch / "out"));
  CHECK(r.exit_code == 1);
  CHECK_THAT(r.err, Catch::StartsWith("epichead track: ") && Catch::Contains("missing"));
}
