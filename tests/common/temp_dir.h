#pragma once
// A fresh directory under the system temp dir for one test, removed when it goes out of scope.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace epichead::testing {

struct TempDir {
  std::filesystem::path path;

  explicit TempDir(const std::string& prefix = "epichead_test") {
    static int counter = 0;
    path = std::filesystem::temp_directory_path() /
           (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string str() const { return path.string(); }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
  // Writes `text` to `name` (parent folders created) and returns the file's path.
  std::string write(const std::string& name, const std::string& text) const {
    const std::filesystem::path p = path / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
};

}  // namespace epichead::testing
