#pragma once
// What the onboard loop records: every CAN frame received and sent (a candump log) and the
// diagnostics stream (JSON lines). On the robot the files are written by a thread of their own,
// fed through bounded lock-free queues, so that a slow disk never holds up the control thread:
// when a queue is full the record is dropped and counted. In the simulator (Mode::Inline) the
// control thread writes them itself, so that a run's files are the same on every run.
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <expected>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "epichead/common/spsc_queue.h"
#include "epichead/firmware_iface/candump_writer.h"

namespace epichead::head {

struct RecorderCounters {
  std::uint64_t frames_logged = 0, frames_dropped = 0;  // candump records written; lost to a full queue
  std::uint64_t lines_written = 0, lines_dropped = 0;   // diagnostics lines written; lost (full queue, too long)
  std::uint64_t write_errors = 0;                       // records the file refused (disk full, ...)
  std::size_t frame_queue_high_water = 0, line_queue_high_water = 0;
};

class Recorder {
 public:
  enum class Mode { Inline, Thread };
  static constexpr std::size_t kMaxLine = 1024;  // a diagnostics line longer than this is dropped (counted)

  // Either path may be empty (that stream is not recorded).
  static std::expected<std::unique_ptr<Recorder>, std::string> open(const std::string& candump_path,
                                                                    const std::string& iface,
                                                                    const std::string& diagnostics_path, Mode mode);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Control thread: never blocks (Mode::Thread) or writes at once (Mode::Inline).
  void frame(const firmware_iface::StampedCanFrame& f, firmware_iface::CanDirection direction);
  void line(std::string_view text);
  // Stops the writer thread after it has written everything queued; closes the files.
  std::expected<void, std::string> close();
  RecorderCounters counters() const;

 private:
  struct FrameRecord {
    firmware_iface::StampedCanFrame frame;
    firmware_iface::CanDirection direction = firmware_iface::CanDirection::Unknown;
  };
  struct LineRecord {
    std::uint16_t size = 0;
    char text[kMaxLine];
  };
  Recorder(std::optional<firmware_iface::CandumpWriter> log, std::string iface, std::FILE* diagnostics,
           std::string diagnostics_path, Mode mode);
  void write_frame(const FrameRecord& r);
  void write_line(const LineRecord& r);
  bool drain();  // writer thread: writes what is queued; whether there was anything
  void writer_loop();

  std::optional<firmware_iface::CandumpWriter> log_;
  std::string iface_;
  std::FILE* diagnostics_ = nullptr;
  std::string diagnostics_path_;
  Mode mode_;
  common::SpscQueue<FrameRecord> frames_;
  common::SpscQueue<LineRecord> lines_;
  LineRecord scratch_;          // control thread: the line being queued (1 KB: kept off the tick's stack)
  LineRecord scratch_written_;  // writer thread: the line being written
  std::atomic<bool> stop_{false};
  std::thread writer_;
  std::atomic<std::uint64_t> frames_logged_{0}, frames_dropped_{0}, lines_written_{0}, lines_dropped_{0},
      write_errors_{0};
  std::string first_error_;  // writer thread until joined
};

}  // namespace epichead::head
