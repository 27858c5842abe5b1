#pragma once
// What the onboard loop records: every CAN frame received and sent (a candump log) and the
// diagnostics stream (JSON lines). On the robot the files are written by a thread of their own,
// fed through bounded lock-free queues, so that a slow disk never holds up the control thread:
// when a queue is full the record is dropped and counted. In the simulator (Mode::Inline) the
// control thread writes them itself, so that a run's files are the same on every run.
//
// The candump log is stamped on the wall clock, as candump stamps (log_clock.h): the writer maps
// each frame's loop stamp through a (monotonic, wall) pair read at open and re-read once a second
// of log time, so the control thread never reads the wall clock. The diagnostics stream keeps the
// loop's stamps; its first line, and one per step of the wall clock, record the mapping:
//   {"t_s":12.000000,"clock_map":{"monotonic_s":12.000000,"unix_s":1704067212.000000}}
//   {"t_s":40.000000,"clock_map":{...},"wall_clock_step_s":-3.000000,"step_followed":false}
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "epichead/common/spsc_queue.h"
#include "epichead/firmware_iface/candump_writer.h"
#include "epichead/head/log_clock.h"
#include "epichead/hw/clock.h"

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

  // Reads the loop's clock and the wall clock at one moment: hw::read_clock_pair on the robot, a
  // fixed pair in the simulator. Called at open and by the writer (never the control thread in
  // Mode::Thread) once a second of log time.
  using ClockPairSource = std::function<hw::ClockPair()>;

  // Either path may be empty (that stream is not recorded).
  static std::expected<std::unique_ptr<Recorder>, std::string> open(const std::string& candump_path,
                                                                    const std::string& iface,
                                                                    const std::string& diagnostics_path, Mode mode,
                                                                    ClockPairSource read_clocks);
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
           std::string diagnostics_path, Mode mode, ClockPairSource read_clocks);
  void write_frame(const FrameRecord& r);
  void write_line(const LineRecord& r);
  void follow_wall_clock(std::int64_t stamp_us);  // writer: re-reads the clock pair once a second of log time
  void write_clock_map(std::int64_t t_us, const char* step);  // writer: a clock_map line
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
  ClockPairSource read_clocks_;
  LogClock log_clock_;                // writer thread: loop stamps -> the log's wall clock
  std::int64_t next_clock_read_us_;   // writer thread: the log time of the next clock-pair reading
  std::atomic<bool> stop_{false};
  std::thread writer_;
  std::atomic<std::uint64_t> frames_logged_{0}, frames_dropped_{0}, lines_written_{0}, lines_dropped_{0},
      write_errors_{0};
  std::string first_error_;  // writer thread until joined
};

}  // namespace epichead::head
