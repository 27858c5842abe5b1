#pragma once
// Runs the built `epichead` program (EPICHEAD_BIN) with shell-quoted arguments, capturing its
// exit code, stdout and stderr, for the end-to-end tests under tests/tools.
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/temp_dir.h"

namespace epichead::testing {

struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The lines of a program's output or a file (without their newlines).
inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// A path as one shell word (the paths tests make hold no single quote).
inline std::string shell_quoted(const std::string& s) { return "'" + s + "'"; }

// `epichead <args>`; the captured streams go through files in `scratch`.
inline ToolRun run_epichead(const TempDir& scratch, const std::string& args) {
  const std::string out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string command = "'" + std::string(EPICHEAD_BIN) + "' " + args + " > '" + out + "' 2> '" + err + "'";
  const int status = std::system(command.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace epichead::testing
