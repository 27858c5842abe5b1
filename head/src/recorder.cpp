#include "recorder.h"

#include <chrono>
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

}  // namespace

Recorder::Recorder(std::optional<firmware_iface::CandumpWriter> log, std::string iface, std::FILE* diagnostics,
                   std::string diagnostics_path, Mode mode)
    : log_(std::move(log)), iface_(std::move(iface)), diagnostics_(diagnostics),
      diagnostics_path_(std::move(diagnostics_path)), mode_(mode), frames_(mode == Mode::Thread ? kFrameQueue : 1),
      lines_(mode == Mode::Thread ? kLineQueue : 1) {
  if (mode_ == Mode::Thread) writer_ = std::thread([this] { writer_loop(); });
}

std::expected<std::unique_ptr<Recorder>, std::string> Recorder::open(const std::string& candump_path,
                                                                     const std::string& iface,
                                                                     const std::string& diagnostics_path, Mode mode) {
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
  return std::unique_ptr<Recorder>(new Recorder(std::move(log), iface, diagnostics, diagnostics_path, mode));
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
  if (auto ok = log_->write(r.frame, iface_, r.direction); ok) {
    frames_logged_.fetch_add(1, std::memory_order_relaxed);
  } else {
    if (first_error_.empty()) first_error_ = ok.error();
    write_errors_.fetch_add(1, std::memory_order_relaxed);
  }
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
