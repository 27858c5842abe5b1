#include "recorder.h"

#include <chrono>
#include <cinttypes>
#include <cstring>

namespace epichead::head {
namespace {

// Queue depths: a candump record is ~100 bytes, so 2^15 of them (3 MB) hold several seconds of a
// busy bus (IMU at 1 kHz, head state and commands at 1 kHz: ~3000 frames/s) while the disk
// stalls; diagnostics come at 10 Hz plus controller events.
constexpr std::size_t kFrameQueue = std::size_t{1} << 15;
constexpr std::size_t kLineQueue = 512;
// The writer sleeps this long when it finds nothing queued: it is no real-time thread, and
// waking it per record would cost the control thread a system call.
constexpr auto kWriterIdle = std::chrono::milliseconds(2);
// How often (log time) the writer re-reads the clock pair, to see a step of the wall clock.
constexpr std::int64_t kClockReadPeriod_us = 1'000'000;

// Microseconds as seconds with six decimals, printed from the integer so that every digit is exact
// (as candump prints its stamps).
int format_seconds(char* out, std::size_t size, std::int64_t us) {
  const char* sign = us < 0 ? "-" : "";
  const std::uint64_t mag = us < 0 ? static_cast<std::uint64_t>(-(us + 1)) + 1 : static_cast<std::uint64_t>(us);
  return std::snprintf(out, size, "%s%" PRIu64 ".%06" PRIu64, sign, mag / 1'000'000, mag % 1'000'000);
}

}  // namespace

Recorder::Recorder(std::optional<firmware_iface::CandumpWriter> log, std::string iface, std::FILE* diagnostics,
                   std::string diagnostics_path, Mode mode, ClockPairSource read_clocks)
    : log_(std::move(log)), iface_(std::move(iface)), diagnostics_(diagnostics),
      diagnostics_path_(std::move(diagnostics_path)), mode_(mode), frames_(mode == Mode::Thread ? kFrameQueue : 1),
      lines_(mode == Mode::Thread ? kLineQueue : 1), read_clocks_(std::move(read_clocks)), log_clock_(read_clocks_()),
      next_clock_read_us_(log_clock_.pair().monotonic_us + kClockReadPeriod_us) {
  // Before the writer starts: the mapping is the stream's first line.
  if (log_) write_clock_map(log_clock_.pair().monotonic_us, nullptr);
  if (mode_ == Mode::Thread) writer_ = std::thread([this] { writer_loop(); });
}

std::expected<std::unique_ptr<Recorder>, std::string> Recorder::open(const std::string& candump_path,
                                                                     const std::string& iface,
                                                                     const std::string& diagnostics_path, Mode mode,
                                                                     ClockPairSource read_clocks) {
  if (!read_clocks) return std::unexpected("recorder: no clock-pair source for the candump log's wall clock");
  std::optional<firmware_iface::CandumpWriter> log;
  if (!candump_path.empty()) {
    auto w = firmware_iface::CandumpWriter::open(candump_path);
    if (!w) return std::unexpected(w.error());
    log.emplace(std::move(*w));
  }
  std::FILE* diagnostics = nullptr;
  if (!diagnostics_path.empty()) {
    diagnostics = std::fopen(diagnostics_path.c_str(), "w");
    if (!diagnostics) return std::unexpected("cannot write " + diagnostics_path);
  }
  return std::unique_ptr<Recorder>(new Recorder(std::move(log), iface, diagnostics, diagnostics_path, mode,
                                                std::move(read_clocks)));
}

Recorder::~Recorder() { (void)close(); }

void Recorder::frame(const firmware_iface::StampedCanFrame& f, firmware_iface::CanDirection direction) {
  if (!log_) return;
  const FrameRecord r{f, direction};
  if (mode_ == Mode::Inline) return write_frame(r);
  if (!frames_.try_push(r)) frames_dropped_.fetch_add(1, std::memory_order_relaxed);
}

void Recorder::line(std::string_view text) {
  if (!diagnostics_) return;
  if (text.size() > kMaxLine) {
    lines_dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  scratch_.size = static_cast<std::uint16_t>(text.size());
  std::memcpy(scratch_.text, text.data(), text.size());
  if (mode_ == Mode::Inline) return write_line(scratch_);
  if (!lines_.try_push(scratch_)) lines_dropped_.fetch_add(1, std::memory_order_relaxed);
}

void Recorder::write_frame(const FrameRecord& r) {
  if (r.frame.stamp_us >= next_clock_read_us_) follow_wall_clock(r.frame.stamp_us);
  const firmware_iface::StampedCanFrame on_wall_clock{log_clock_.unix_us(r.frame.stamp_us), r.frame.frame};
  if (auto ok = log_->write(on_wall_clock, iface_, r.direction); ok) {
    frames_logged_.fetch_add(1, std::memory_order_relaxed);
  } else {
    if (first_error_.empty()) first_error_ = ok.error();
    write_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

void Recorder::follow_wall_clock(std::int64_t stamp_us) {
  next_clock_read_us_ = stamp_us + kClockReadPeriod_us;
  switch (log_clock_.update(read_clocks_())) {
    case LogClock::Update::Same: return;
    case LogClock::Update::StepFollowed: return write_clock_map(stamp_us, "true");
    case LogClock::Update::StepNotFollowed: return write_clock_map(stamp_us, "false");
  }
}

void Recorder::write_clock_map(std::int64_t t_us, const char* step_followed) {
  if (!diagnostics_) return;
  char t[32], mono[32], unix_s[32], step[32];
  format_seconds(t, sizeof t, t_us);
  format_seconds(mono, sizeof mono, log_clock_.pair().monotonic_us);
  format_seconds(unix_s, sizeof unix_s, log_clock_.pair().unix_us);
  LineRecord& r = scratch_written_;
  const int n = step_followed
                    ? (format_seconds(step, sizeof step, log_clock_.last_step_us()),
                       std::snprintf(r.text, kMaxLine,
                                     "{\"t_s\":%s,\"clock_map\":{\"monotonic_s\":%s,\"unix_s\":%s},"
                                     "\"wall_clock_step_s\":%s,\"step_followed\":%s}",
                                     t, mono, unix_s, step, step_followed))
                    : std::snprintf(r.text, kMaxLine, "{\"t_s\":%s,\"clock_map\":{\"monotonic_s\":%s,\"unix_s\":%s}}",
                                    t, mono, unix_s);
  r.size = static_cast<std::uint16_t>(n);
  write_line(r);
}

void Recorder::write_line(const LineRecord& r) {
  if (std::fwrite(r.text, 1, r.size, diagnostics_) == r.size && std::fputc('\n', diagnostics_) != EOF) {
    lines_written_.fetch_add(1, std::memory_order_relaxed);
  } else {
    if (first_error_.empty()) first_error_ = diagnostics_path_ + ": write error";
    write_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

bool Recorder::drain() {
  bool any = false;
  FrameRecord f;
  while (frames_.try_pop(f)) {
    write_frame(f);
    any = true;
  }
  while (lines_.try_pop(scratch_written_)) {
    write_line(scratch_written_);
    any = true;
  }
  return any;
}

void Recorder::writer_loop() {
  for (;;) {
    const bool stopping = stop_.load(std::memory_order_acquire);
    if (drain()) continue;
    if (stopping) return;  // stop was asked before this empty drain: nothing is left
    if (diagnostics_) std::fflush(diagnostics_);  // a reader (tail -f) sees lines within a few ms
    std::this_thread::sleep_for(kWriterIdle);
  }
}

std::expected<void, std::string> Recorder::close() {
  if (writer_.joinable()) {
    stop_.store(true, std::memory_order_release);
    writer_.join();
  }
  std::string error = first_error_;
  if (log_) {
    if (auto ok = log_->close(); !ok && error.empty()) error = ok.error();
    log_.reset();
  }
  if (diagnostics_) {
    if (std::fclose(diagnostics_) != 0 && error.empty()) error = diagnostics_path_ + ": error while closing";
    diagnostics_ = nullptr;
  }
  if (!error.empty()) return std::unexpected(error);
  return {};
}

RecorderCounters Recorder::counters() const {
  RecorderCounters c;
  c.frames_logged = frames_logged_.load(std::memory_order_relaxed);
  c.frames_dropped = frames_dropped_.load(std::memory_order_relaxed);
  c.lines_written = lines_written_.load(std::memory_order_relaxed);
  c.lines_dropped = lines_dropped_.load(std::memory_order_relaxed);
  c.write_errors = write_errors_.load(std::memory_order_relaxed);
  c.frame_queue_high_water = frames_.high_water();
  c.line_queue_high_water = lines_.high_water();
  return c;
}

}  // namespace epichead::head
