#pragma once
// Writes frames as a candump log (format: candump_line.h) through a buffered FILE, for the
// simulator's bus and the onboard loop's recorder. No allocation per frame.
#include <cstdint>
#include <cstdio>
#include <expected>
#include <string>
#include <string_view>

#include "epichead/firmware_iface/candump_line.h"

namespace epichead::firmware_iface {

class CandumpWriter {
 public:
  static std::expected<CandumpWriter, std::string> open(const std::string& path);
  CandumpWriter(CandumpWriter&&) noexcept;
  CandumpWriter& operator=(CandumpWriter&&) noexcept;
  ~CandumpWriter();  // closes (errors at close are lost: call close() to see them)

  // Appends one frame; the iface name is written as given (no spaces).
  std::expected<void, std::string> write(const StampedCanFrame& frame, std::string_view iface,
                                         CanDirection direction = CanDirection::Unknown);
  std::expected<void, std::string> close();
  std::uint64_t frames() const { return frames_; }

 private:
  CandumpWriter(std::FILE* f, std::string path) : file_(f), path_(std::move(path)) {}
  std::FILE* file_ = nullptr;
  std::string path_;
  std::uint64_t frames_ = 0;
};

}  // namespace epichead::firmware_iface
