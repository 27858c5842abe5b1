#include "epichead/firmware_iface/candump_reader.h"

#include <cerrno>
#include <cstring>
#include <utility>

namespace epichead::firmware_iface {

namespace {
// Longer lines are not candump output (the longest, CAN FD with 64 bytes, is under 200).
constexpr std::size_t kMaxLine = 4096;
}  // namespace

std::string CandumpLineError::message(std::string_view path) const {
  return std::string(path) + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + reason;
}

std::expected<CandumpReader, std::string> CandumpReader::open(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return std::unexpected(path + ": cannot open (" + std::strerror(errno) + ")");
  CandumpReader r;
  r.file_ = f;
  r.buffer_ = std::make_unique<char[]>(kBufferBytes);
  r.pos_ = r.end_ = r.buffer_.get();
  return r;
}

CandumpReader CandumpReader::from_memory(std::string_view text) {
  CandumpReader r;
  r.memory_ = text;
  r.pos_ = text.data();
  r.end_ = text.data() + text.size();
  r.eof_ = true;
  return r;
}

CandumpReader::CandumpReader(CandumpReader&& o) noexcept { *this = std::move(o); }

CandumpReader& CandumpReader::operator=(CandumpReader&& o) noexcept {
  if (this == &o) return *this;
  if (file_) std::fclose(file_);
  file_ = std::exchange(o.file_, nullptr);
  buffer_ = std::move(o.buffer_);
  memory_ = o.memory_;
  pos_ = o.pos_;
  end_ = o.end_;
  eof_ = o.eof_;
  skipping_long_line_ = o.skipping_long_line_;
  line_ = o.line_;
  frames_ = o.frames_;
  malformed_ = o.malformed_;
  consumed_total_ = o.consumed_total_;
  errors_ = std::move(o.errors_);
  handler_ = std::move(o.handler_);
  io_error_ = std::move(o.io_error_);
  return *this;
}

CandumpReader::~CandumpReader() {
  if (file_) std::fclose(file_);
}

bool CandumpReader::fill() {
  if (eof_ || !file_) return false;
  // Keep the unread tail, then read after it.
  const std::size_t tail = static_cast<std::size_t>(end_ - pos_);
  std::memmove(buffer_.get(), pos_, tail);
  pos_ = buffer_.get();
  end_ = buffer_.get() + tail;
  const std::size_t got = std::fread(const_cast<char*>(end_), 1, kBufferBytes - tail, file_);
  end_ += got;
  if (got == 0) {
    if (std::ferror(file_)) io_error_ = std::string("read error: ") + std::strerror(errno);
    eof_ = true;
    return false;
  }
  return true;
}

void CandumpReader::report(int column, const char* reason) {
  ++malformed_;
  if (errors_.size() < kKeptErrors || handler_) {
    CandumpLineError e{line_, column, reason};
    if (handler_) handler_(e);
    if (errors_.size() < kKeptErrors) errors_.push_back(std::move(e));
  }
}

bool CandumpReader::next(CandumpRecord& out) {
  for (;;) {
    const char* nl = static_cast<const char*>(std::memchr(pos_, '\n', static_cast<std::size_t>(end_ - pos_)));
    if (!nl) {
      if (static_cast<std::size_t>(end_ - pos_) > kMaxLine) {
        // A line longer than any candump line: report it once and drop what we have of it.
        if (!skipping_long_line_) {
          ++line_;
          report(1, "line too long (not a candump line)");
          skipping_long_line_ = true;
        }
        consumed_total_ += static_cast<std::uint64_t>(end_ - pos_);
        pos_ = end_;
      }
      if (fill()) continue;
      if (pos_ == end_) return false;
      nl = end_;  // last line without a newline
    }
    const std::string_view line(pos_, static_cast<std::size_t>(nl - pos_));
    consumed_total_ += line.size() + (nl < end_ ? 1 : 0);
    pos_ = nl < end_ ? nl + 1 : end_;
    if (skipping_long_line_) {  // the rest of an over-long line
      skipping_long_line_ = false;
      continue;
    }
    ++line_;
    const CandumpParse r = parse_candump_line(line, out);
    if (r.kind == CandumpLineKind::Frame) {
      ++frames_;
      return true;
    }
    if (r.kind == CandumpLineKind::Malformed) report(r.column, r.reason);
  }
}

}  // namespace epichead::firmware_iface
