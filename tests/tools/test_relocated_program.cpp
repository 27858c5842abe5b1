// The program carries its built-in scenarios and scene assets: a copy of the binary outside the
// source tree, run from another directory, simulates a built-in scenario (issue 20: the VM test
// failed when the checkout was under /tmp, because the program read them from the source tree).
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include "common/run_tool.h"
#include "common/temp_dir.h"

namespace fs = std::filesystem;
using epichead::testing::shell_quoted;
using epichead::testing::slurp;
using epichead::testing::TempDir;

namespace {

struct Run {
  int exit_code = -1;
  std::string out, err;
};

// `program args` run from `cwd`.
Run run_in(const fs::path& cwd, const fs::path& program, const std::string& args, const TempDir& scratch) {
  const std::string out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string command = "cd " + shell_quoted(cwd.string()) + " && " + shell_quoted(program.string()) + " " + args +
                              " > " + shell_quoted(out) + " 2> " + shell_quoted(err);
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

}  // namespace

TEST_CASE("a copy of the program outside the source tree simulates built-in scenarios", "[tools][relocated]") {
  TempDir scratch("epichead_test_relocated");
  const fs::path source(EPICHEAD_SOURCE_DIR);
  REQUIRE(!fs::path(scratch.str()).string().starts_with(source.string()));
  const fs::path bin = scratch.path / "opt" / "bin" / "epichead";
  fs::create_directories(bin.parent_path());
  fs::copy_file(EPICHEAD_BIN, bin);
  const fs::path cwd = scratch.path / "elsewhere";
  fs::create_directories(cwd);

  // Nothing in the binary points at the source tree's scenarios or scenes.
  const std::string image = slurp(bin.string());
  CHECK(image.find((source / "sim" / "scenarios").string()) == std::string::npos);
  CHECK(image.find((source / "sim" / "scenes").string()) == std::string::npos);

  // box_clutter: its scenario, its model and three photos, all from the program itself.
  const Run r = run_in(cwd, bin, "sim box_clutter --out seq --frames 2", scratch);
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(fs::exists(cwd / "seq" / "frames" / "000001.png"));
  CHECK(slurp((cwd / "seq" / "model.cao").string()) == slurp((source / "sim" / "scenes" / "box_clutter.cao").string()));

  // A user's scenario file by path still works (with scene variety, which may show any photo).
  const TempDir user("epichead_test_relocated_scn");
  const std::string scn = user.write("mine.scn", "scene can\nframes 2\nmotion handheld\nvariety 1\nseed 5\n");
  const Run file = run_in(cwd, bin, "sim " + shell_quoted(scn) + " --out seq2", scratch);
  INFO(file.out << file.err);
  CHECK(file.exit_code == 0);
  CHECK(slurp((cwd / "seq2" / "model.cao").string()) == slurp((source / "sim" / "scenes" / "can.cao").string()));
}
