// One candump log line (candump_line.h). Properties: the parser never reads out of bounds and
// yields only frames the bus can carry (impossible_frame_reason); a malformed line's column lies on the line (or one
// past it); a parsed frame, formatted by the writer into a buffer of exactly kCandumpMaxLine
// bytes, reads back as the same frame, stamp, interface and direction.
#include <cstring>
#include <memory>
#include <string>

#include "epichead/firmware_iface/candump_line.h"
#include "fuzz_support.h"

using namespace epichead::firmware_iface;
using epichead::fuzz::check;

namespace {

std::string describe(const CanFrame& f) {
  std::string s = "id " + std::to_string(f.id) + " flags " + std::to_string(static_cast<int>(f.flags)) + " len " +
                  std::to_string(f.len);
  return s;
}

void check_possible(const CanFrame& f) {
  const char* why = impossible_frame_reason(f);
  check(why == nullptr, "the parser yields a frame no bus carries: " + describe(f) + ": " + (why ? why : ""));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The reader hands the parser one line without its '\n'.
  std::string_view line = epichead::fuzz::as_text(data, size);
  if (line.find('\n') != std::string_view::npos) line = line.substr(0, line.find('\n'));
  // A copy of exactly the line's size, so ASan sees any read past its end.
  std::unique_ptr<char[]> copy(new char[line.size() + 1]);
  std::memcpy(copy.get(), line.data(), line.size());
  const std::string_view exact(copy.get(), line.size());

  CandumpRecord rec;
  const CandumpParse p = parse_candump_line(exact, rec);
  if (p.kind == CandumpLineKind::Malformed) {
    check(p.reason != nullptr && p.reason[0] != '\0', "malformed without a reason");
    check(p.column >= 1 && static_cast<std::size_t>(p.column) <= exact.size() + 1,
          "column " + std::to_string(p.column) + " outside a line of " + std::to_string(exact.size()) + " bytes (" +
              p.reason + ")");
    return 0;
  }
  if (p.kind != CandumpLineKind::Frame) return 0;
  check_possible(rec.frame.frame);

  // Round trip through the writer.
  std::unique_ptr<char[]> buf(new char[kCandumpMaxLine]);
  // The writer cuts a name longer than Linux allows (kCandumpMaxIface).
  const std::string iface(rec.iface.substr(0, kCandumpMaxIface));
  const std::size_t n = format_candump_line(rec.frame, rec.iface, buf.get(), rec.direction);
  check(n > 0 && n <= kCandumpMaxLine, "format length " + std::to_string(n));
  check(buf[n - 1] == '\n', "formatted line does not end with a newline");
  const std::string written(buf.get(), n - 1);
  CandumpRecord back;
  const CandumpParse q = parse_candump_line(written, back);
  check(q.kind == CandumpLineKind::Frame, "written line does not read back: '" + written + "': " + q.reason);
  const CanFrame& a = rec.frame.frame;
  const CanFrame& b = back.frame.frame;
  check(a.id == b.id && a.flags == b.flags && a.len == b.len, "frame changed: " + describe(a) + " -> " + describe(b) +
                                                                  " via '" + written + "'");
  const int data_len = a.remote() ? 0 : a.len;
  check(std::memcmp(a.data.data(), b.data.data(), static_cast<std::size_t>(data_len)) == 0, "data changed via '" + written + "'");
  check(back.frame.stamp_us == rec.frame.stamp_us, "stamp changed via '" + written + "'");
  check(back.iface == iface, "interface changed via '" + written + "'");
  check(back.direction == rec.direction, "direction changed via '" + written + "'");
  return 0;
}
