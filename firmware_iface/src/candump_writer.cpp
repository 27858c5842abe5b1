#include "epichead/firmware_iface/candump_writer.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

namespace epichead::firmware_iface {
namespace {

constexpr std::int64_t kMaxStampUs = 1'000'000'000'000LL * 1'000'000;

std::string hex_id(std::uint32_t id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%X", static_cast<unsigned>(id));
  return buf;
}

}  // namespace

std::expected<CandumpWriter, std::string> CandumpWriter::open(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return std::unexpected(path + ": cannot open for writing (" + std::strerror(errno) + ")");
  return CandumpWriter(f, path);
}

CandumpWriter::CandumpWriter(CandumpWriter&& o) noexcept { *this = std::move(o); }

CandumpWriter& CandumpWriter::operator=(CandumpWriter&& o) noexcept {
  if (this == &o) return *this;
  if (file_) std::fclose(file_);
  file_ = std::exchange(o.file_, nullptr);
  path_ = std::move(o.path_);
  frames_ = o.frames_;
  return *this;
}

CandumpWriter::~CandumpWriter() {
  if (file_) std::fclose(file_);
}

std::expected<void, std::string> CandumpWriter::write(const StampedCanFrame& frame, std::string_view iface,
                                                      CanDirection direction) {
  if (!file_) return std::unexpected(path_ + ": writer is closed");
  if (const char* why = candump_iface_problem(iface))
    return std::unexpected(path_ + ": interface name '" + std::string(iface) + "' " + why);
  if (const char* why = impossible_frame_reason(frame.frame))
    return std::unexpected(path_ + ": cannot record CAN id 0x" + hex_id(frame.frame.id) + ": " + why);
  // The reader takes (seconds.microseconds) with 1 to 12 digits of seconds, none negative.
  if (frame.stamp_us < 0 || frame.stamp_us >= kMaxStampUs)
    return std::unexpected(path_ + ": cannot record a frame stamped " + std::to_string(frame.stamp_us) +
                           " us: a candump stamp is 0 to 10^12 s");
  char line[kCandumpMaxLine];
  const std::size_t n = format_candump_line(frame, iface, line, direction);
  if (std::fwrite(line, 1, n, file_) != n) return std::unexpected(path_ + ": write error (" + std::strerror(errno) + ")");
  ++frames_;
  return {};
}

std::expected<void, std::string> CandumpWriter::close() {
  if (!file_) return {};
  const int rc = std::fclose(std::exchange(file_, nullptr));
  if (rc != 0) return std::unexpected(path_ + ": error while closing (" + std::strerror(errno) + ")");
  return {};
}

}  // namespace epichead::firmware_iface
