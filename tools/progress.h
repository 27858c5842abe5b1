#pragma once
// Progress of a long command on a terminal: one line on stderr, rewritten in place with '\r'
// ("sim: 120/300 frames  41.2 frames/s  0:04 left"), at most ten times a second, ended with a
// newline. When stderr is not a terminal (a log, a pipe, a test) it writes nothing at all, so
// logs and scripts see only the command's own messages.
//
// update() is cheap enough to call every simulated tick: it reads the clock and returns unless a
// tenth of a second has passed; it formats into a fixed buffer and writes with write(2), so it
// never allocates and never touches stdio's buffers.
#include <chrono>
#include <cstddef>

namespace epichead::tools {

// The line for `done` of `total` (total <= 0: unknown, no time left) after `elapsed_s`, into
// `buffer` (always terminated, cut to fit). Returns its length. `final`: the closing line, with
// the time taken in place of the time left.
std::size_t format_progress(char* buffer, std::size_t size, const char* label, const char* unit, long done, long total,
                            double elapsed_s, bool final);

class Progress {
 public:
  static constexpr double kMinInterval_s = 0.1;  // ten updates a second at most

  // Shows progress on stderr when it is a terminal. `label` and `unit` must outlive the object
  // (string literals, or a string the caller keeps).
  Progress(const char* label, const char* unit, long total);
  // The same on `fd`, shown when `fd` is a terminal (tests use a pseudo-terminal).
  Progress(const char* label, const char* unit, long total, int fd);
  ~Progress();  // wipes the line when finish() was not called (the command failed)
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  bool shown() const { return fd_ >= 0; }
  void set_total(long total) { total_ = total; }
  long total() const { return total_; }

  // `done` of the total so far: the line is redrawn when a tenth of a second has passed since the
  // last drawing (the first call draws).
  void update(long done);
  // The same at a given time since the start (tests: throttling without sleeping).
  void update_at(long done, double elapsed_s);
  // Wipes the line so that another message can be printed on the terminal; the next update
  // draws it again.
  void clear();
  // The closing line (what was done, the rate, the time taken) and a newline. Once; nothing when
  // nothing was drawn. `done` >= 0: the count to show, else the last update's.
  void finish(long done = -1);

  int drawings() const { return drawings_; }  // lines drawn so far (tests)

  // Wipes the line of the progress being shown, if any: fail() calls it so that an error
  // message starts on a clean line.
  static void clear_current();

 private:
  void draw(long done, double elapsed_s, bool final);

  const char* label_;
  const char* unit_;
  long total_;
  int fd_ = -1;  // -1: not a terminal, nothing is written
  std::chrono::steady_clock::time_point start_;
  double last_drawn_s_ = -1;
  long last_done_ = 0;
  std::size_t last_length_ = 0;
  int drawings_ = 0;
  bool finished_ = false;
  Progress* outer_ = nullptr;  // the progress shown before this one (nested: a command's and its templates')
};

}  // namespace epichead::tools
