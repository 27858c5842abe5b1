#pragma once
// Shared bits of the fuzz targets (tests/fuzz/fuzz_*.cpp): a scratch folder for readers that
// take a path, splitting one input into several files, and the check that fails a run.
// Each target defines LLVMFuzzerTestOneInput; libFuzzer (clang build, ./dev fuzz) or
// replay_main.cpp (GCC test build, ctest fuzz/<target>) calls it.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace epichead::fuzz {

// A property of the code under test does not hold: print what, and abort so that libFuzzer
// saves the input as a crash and the replay test fails.
[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "fuzz property violated: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

inline void check(bool ok, const std::string& what) {
  if (!ok) fail(what);
}

// One folder per process under the system temp dir, emptied at each input and removed at exit.
class Scratch {
 public:
  static Scratch& get() {
    static Scratch scratch;
    return scratch;
  }
  const std::filesystem::path& path() const { return path_; }
  // Removes what the previous input left.
  void clear() {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(path_, ec)) std::filesystem::remove_all(entry, ec);
  }
  // Writes bytes to `name` in the folder; returns the file's path.
  std::string write(const std::string& name, std::string_view bytes) const {
    const std::filesystem::path p = path_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p.string();
  }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }

 private:
  Scratch() {
    path_ = std::filesystem::temp_directory_path() / ("epichead_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(path_);
  }
  std::filesystem::path path_;
};

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Splits `text` at every occurrence of `separator` (a line of its own in the seeds, so that a
// fuzzer mutating one file keeps the others).
inline std::vector<std::string_view> split(std::string_view text, std::string_view separator) {
  std::vector<std::string_view> parts;
  for (;;) {
    const std::size_t at = text.find(separator);
    if (at == std::string_view::npos) break;
    parts.push_back(text.substr(0, at));
    text.remove_prefix(at + separator.size());
  }
  parts.push_back(text);
  return parts;
}

// Messages are one line: the tools print them as the one-line reason of a failure.
inline void check_one_line(const std::string& message, std::string_view what) {
  check(!message.empty(), std::string(what) + ": empty error message");
  check(message.find('\n') == std::string::npos, std::string(what) + ": error message spans lines: " + message);
}

// Reads the bytes at the front of an input, little-endian; zero past its end.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  std::size_t left() const { return pos_ < size_ ? size_ - pos_ : 0; }
  std::uint8_t u8() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t{u8()} << (8 * i);
    return v;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace epichead::fuzz

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
