#pragma once
// Streams a candump log (file or memory) record by record in constant memory: a fixed read
// buffer, no allocation per line. A malformed line is counted, reported with its line number
// (the first kKeptErrors are kept, and an optional callback sees all) and skipped.
#include <cstdint>
#include <cstdio>
#include <expected>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "epichead/firmware_iface/candump_line.h"

namespace epichead::firmware_iface {

struct CandumpLineError {
  std::uint64_t line = 0;  // 1-based
  int column = 0;
  std::string reason;      // "1234:17: bad hex digit in data" is what message() prints
  std::string message(std::string_view path) const;
};

class CandumpReader {
 public:
  static constexpr std::size_t kBufferBytes = 1 << 20;
  static constexpr std::size_t kKeptErrors = 20;

  // Opens a file; the error says which and why.
  static std::expected<CandumpReader, std::string> open(const std::string& path);
  // Reads from memory the caller keeps alive (tests, benchmarks).
  static CandumpReader from_memory(std::string_view text);

  CandumpReader(CandumpReader&&) noexcept;
  CandumpReader& operator=(CandumpReader&&) noexcept;
  ~CandumpReader();

  // The next frame; false at the end of the input. `out.iface` is valid until the next call.
  bool next(CandumpRecord& out);

  // Called for every malformed line (optional).
  void on_error(std::function<void(const CandumpLineError&)> handler) { handler_ = std::move(handler); }

  std::uint64_t lines() const { return line_; }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t malformed() const { return malformed_; }
  std::uint64_t bytes_read() const { return consumed_total_; }
  const std::vector<CandumpLineError>& first_errors() const { return errors_; }
  // An I/O error while reading, empty if none.
  const std::string& io_error() const { return io_error_; }

 private:
  CandumpReader() = default;
  bool fill();  // reads more of the file; false at end of file
  void report(int column, const char* reason);

  std::FILE* file_ = nullptr;
  std::unique_ptr<char[]> buffer_;
  std::string_view memory_;
  const char* pos_ = nullptr;
  const char* end_ = nullptr;
  bool eof_ = false;
  bool skipping_long_line_ = false;
  std::uint64_t line_ = 0, frames_ = 0, malformed_ = 0, consumed_total_ = 0;
  std::vector<CandumpLineError> errors_;
  std::function<void(const CandumpLineError&)> handler_;
  std::string io_error_;
};

}  // namespace epichead::firmware_iface
