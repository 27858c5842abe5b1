#include "progress.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <unistd.h>

namespace epichead::tools {

namespace {

// "m:ss" or "h:mm:ss", rounded to the second.
void format_duration(char* buffer, std::size_t size, double seconds) {
  const long s = std::lround(std::clamp(seconds, 0.0, 1e9));
  if (s < 3600) std::snprintf(buffer, size, "%ld:%02ld", s / 60, s % 60);
  else std::snprintf(buffer, size, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
}

// Appends with snprintf semantics: `used` never passes size - 1.
template <typename... Args>
void append(char* buffer, std::size_t size, std::size_t& used, const char* format, Args... args) {
  if (used + 1 >= size) return;
  const int n = std::snprintf(buffer + used, size - used, format, args...);
  if (n > 0) used = std::min(size - 1, used + static_cast<std::size_t>(n));
}

// The whole of `text` on `fd` (a terminal: short writes and EINTR only); errors are dropped,
// since progress must never stop the command.
void write_all(int fd, const char* text, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, text, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return;
    text += w;
    n -= static_cast<std::size_t>(w);
  }
}

Progress* current = nullptr;  // the innermost progress shown (one thread draws progress)

}  // namespace

std::size_t format_progress(char* buffer, std::size_t size, const char* label, const char* unit, long done, long total,
                            double elapsed_s, bool final) {
  if (size == 0) return 0;
  buffer[0] = '\0';
  std::size_t used = 0;
  if (total > 0) append(buffer, size, used, "%s: %ld/%ld %s", label, done, total, unit);
  else append(buffer, size, used, "%s: %ld %s", label, done, unit);
  const double rate = elapsed_s > 0 && done > 0 ? static_cast<double>(done) / elapsed_s : 0.0;
  if (rate > 0) append(buffer, size, used, rate < 10 ? "  %.2f %s/s" : "  %.1f %s/s", rate, unit);
  char duration[32];
  if (final) {
    format_duration(duration, sizeof duration, elapsed_s);
    append(buffer, size, used, "  %s taken", duration);
  } else if (total > 0 && rate > 0 && done < total) {
    format_duration(duration, sizeof duration, static_cast<double>(total - done) / rate);
    append(buffer, size, used, "  %s left", duration);
  }
  return used;
}

Progress::Progress(const char* label, const char* unit, long total) : Progress(label, unit, total, STDERR_FILENO) {}

Progress::Progress(const char* label, const char* unit, long total, int fd)
    : label_(label), unit_(unit), total_(total), fd_(::isatty(fd) ? fd : -1), start_(std::chrono::steady_clock::now()) {
  if (fd_ < 0) return;
  outer_ = current;
  current = this;
}

Progress::~Progress() {
  if (fd_ < 0) return;
  if (!finished_) clear();
  if (current == this) current = outer_;
}

void Progress::clear_current() {
  if (current) current->clear();
}

void Progress::update(long done) {
  if (fd_ < 0 || finished_) return;
  update_at(done, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
}

void Progress::update_at(long done, double elapsed_s) {
  if (fd_ < 0 || finished_) return;
  last_done_ = done;
  if (last_drawn_s_ >= 0 && elapsed_s - last_drawn_s_ < kMinInterval_s) return;
  last_drawn_s_ = elapsed_s;
  draw(done, elapsed_s, false);
}

void Progress::clear() {
  if (fd_ < 0 || last_length_ == 0) return;
  char blank[258];
  const std::size_t n = std::min(last_length_, sizeof blank - 2);
  blank[0] = '\r';
  std::memset(blank + 1, ' ', n);
  blank[n + 1] = '\r';
  write_all(fd_, blank, n + 2);
  last_length_ = 0;
  last_drawn_s_ = -1;
}

void Progress::finish(long done) {
  if (fd_ < 0 || finished_ || drawings_ == 0) return;
  if (done >= 0) last_done_ = done;
  draw(last_done_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(), true);
  finished_ = true;
}

void Progress::draw(long done, double elapsed_s, bool final) {
  // '\r', the line, blanks over the rest of a longer earlier line, and on the last a newline.
  char line[256];
  line[0] = '\r';
  std::size_t n = 1 + format_progress(line + 1, sizeof line - 2, label_, unit_, done, total_, elapsed_s, final);
  const std::size_t length = n - 1;
  while (n - 1 < last_length_ && n < sizeof line - 1) line[n++] = ' ';
  if (final) line[n++] = '\n';
  write_all(fd_, line, n);
  last_length_ = final ? 0 : length;
  ++drawings_;
}

}  // namespace epichead::tools
