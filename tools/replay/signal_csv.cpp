#include "replay/signal_csv.h"

#include <cerrno>
#include <cinttypes>
#include <cstring>
#include <string_view>

namespace epichead::tools::replay {

namespace fw = firmware_iface;

namespace {

void put_text(std::FILE* f, std::string_view s) {
  if (s.empty()) return;  // (an empty view may hold a null pointer, which fwrite must not get)
  if (s.find_first_of(",\"\n\r") == std::string_view::npos) {
    std::fwrite(s.data(), 1, s.size(), f);
    return;
  }
  std::fputc('"', f);
  for (char c : s) {
    if (c == '"') std::fputc('"', f);
    std::fputc(c, f);
  }
  std::fputc('"', f);
}

// sec.usec from integer microseconds, exact (no rounding through a double).
void put_stamp(std::FILE* f, std::int64_t us) {
  const bool negative = us < 0;
  const std::uint64_t mag = negative ? 0 - static_cast<std::uint64_t>(us) : static_cast<std::uint64_t>(us);
  std::fprintf(f, "%s%" PRIu64 ".%06" PRIu64, negative ? "-" : "", mag / 1'000'000, mag % 1'000'000);
}

}  // namespace

std::expected<SignalCsv, std::string> SignalCsv::open(const std::string& path) {
  SignalCsv c;
  c.path_ = path;
  c.file_.reset(std::fopen(path.c_str(), "wb"));
  if (!c.file_) return std::unexpected(path + ": cannot create (" + std::strerror(errno) + ")");
  std::fputs("t_s,id,message,signal,raw,value,unit,text\n", c.file_.get());
  return c;
}

void SignalCsv::write(const DecodedSignal& d) {
  std::FILE* f = file_.get();
  if (!f) return;
  const fw::CanFrame& frame = d.record->frame.frame;
  if (d.record->has_stamp) put_stamp(f, d.record->frame.stamp_us);
  std::fprintf(f, frame.extended() ? ",0x%08X," : ",0x%03X,", static_cast<unsigned>(frame.id));
  put_text(f, d.message->name);
  std::fputc(',', f);
  put_text(f, d.signal->name);
  const fw::DbcSignal& s = *d.signal;
  std::string_view text;
  if (s.value_type == fw::SignalValueType::Integer) {
    const std::int64_t raw = d.value->raw_signed(s);
    if (s.is_signed) std::fprintf(f, ",%" PRId64, raw);
    else std::fprintf(f, ",%" PRIu64, d.value->bits);
    text = fw::value_text(s, raw);
  } else {
    std::fprintf(f, s.value_type == fw::SignalValueType::Float32 ? ",%.9g" : ",%.17g", d.value->raw);
  }
  // 15 significant digits: the decimal a DBC's factor gives (0.1 * 3 prints 0.3), exact for
  // integers up to 10^15.
  std::fprintf(f, ",%.15g,", d.value->physical);
  put_text(f, s.unit);
  std::fputc(',', f);
  put_text(f, text);
  std::fputc('\n', f);
  ++rows_;
}

std::expected<void, std::string> SignalCsv::close() {
  std::FILE* f = file_.release();
  if (!f) return {};
  const bool failed = std::ferror(f) != 0;
  if (std::fclose(f) != 0 || failed) return std::unexpected(path_ + ": write error (disk full?)");
  return {};
}

}  // namespace epichead::tools::replay
