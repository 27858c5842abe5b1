// Progress of long commands (tools/progress.h): a line rewritten in place on a terminal, at most
// ten times a second, and nothing at all when stderr is a file or a pipe. The terminal is a
// pseudo-terminal (openpty), so the path a user sees is the one tested, through the program too.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <string>
#include <vector>

#include "common/run_tool.h"
#include "common/temp_dir.h"
#include "progress.h"

namespace {

using epichead::testing::run_epichead;
using epichead::testing::TempDir;
using epichead::tools::format_progress;
using epichead::tools::Progress;
const auto& q = epichead::testing::shell_quoted;

std::string formatted(long done, long total, double elapsed_s, bool final) {
  char buffer[160];
  const std::size_t n = format_progress(buffer, sizeof buffer, "sim", "frames", done, total, elapsed_s, final);
  CHECK(n == std::string(buffer).size());
  return buffer;
}

// A pseudo-terminal: what the program writes to `slave` is read from `master`.
struct Pty {
  int master = -1, slave = -1;
  Pty() {
    REQUIRE(::openpty(&master, &slave, nullptr, nullptr, nullptr) == 0);
    // Non-blocking reads: drain() takes what is there.
    ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
  }
  ~Pty() {
    if (slave >= 0) ::close(slave);
    if (master >= 0) ::close(master);
  }
  std::string drain() const {
    std::string text;
    char buffer[4096];
    for (ssize_t n; (n = ::read(master, buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(n));
    return text;
  }
};

// `PROGRAM ARGS...` with stderr on a pseudo-terminal (stdout to a file, stdin from /dev/null):
// the exit code and what reached the terminal.
struct PtyRun {
  int exit_code = -1;
  std::string terminal;
};

PtyRun run_on_pty(const TempDir& scratch, const std::string& program, const std::vector<std::string>& args) {
  int master = -1, slave = -1;
  REQUIRE(::openpty(&master, &slave, nullptr, nullptr, nullptr) == 0);
  // Everything the child needs is made before fork: it only redirects and execs.
  std::vector<std::string> words{program};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const std::string out_path = scratch / "stdout.txt";
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = ::open("/dev/null", O_RDONLY);
    if (out < 0 || in < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(slave, 2) < 0) ::_exit(126);
    ::close(master);
    ::close(slave);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(slave);
  PtyRun r;
  char buffer[4096];
  for (;;) {  // until the child's end of the terminal is closed (read then fails with EIO)
    const ssize_t n = ::read(master, buffer, sizeof buffer);
    if (n > 0) r.terminal.append(buffer, static_cast<std::size_t>(n));
    else if (n < 0 && errno == EINTR) continue;
    else break;
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ::close(master);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

PtyRun run_with_stderr_on_pty(const TempDir& scratch, const std::vector<std::string>& args) {
  return run_on_pty(scratch, EPICHEAD_BIN, args);
}

// A script using tools/progress.sh, as results.sh and heldout.sh do.
const std::string kShellProgress = ". '" EPICHEAD_SOURCE_DIR "/tools/progress.sh'; set -eu; progress_start demo 3 runs; "
                                   "progress_step; progress_say 'demo: a message'; progress_step 2; progress_end; echo end";

}  // namespace

TEST_CASE("progress line: frames done of the total, the rate and the time left, then the time taken") {
  CHECK(formatted(0, 300, 0.0, false) == "sim: 0/300 frames");
  CHECK(formatted(120, 300, 3.0, false) == "sim: 120/300 frames  40.0 frames/s  0:05 left");  // 4.5 s, rounded
  CHECK(formatted(3, 300, 2.0, false) == "sim: 3/300 frames  1.50 frames/s  3:18 left");
  CHECK(formatted(30, 3000, 1.0, false) == "sim: 30/3000 frames  30.0 frames/s  1:39 left");
  CHECK(formatted(1, 5000, 1.0, false) == "sim: 1/5000 frames  1.00 frames/s  1:23:19 left");
  CHECK(formatted(300, 300, 7.4, true) == "sim: 300/300 frames  40.5 frames/s  0:07 taken");
  CHECK(formatted(12, 0, 2.0, false) == "sim: 12 frames  6.00 frames/s");  // total unknown: no time left
  // A small buffer cuts the line and still terminates it.
  char small[12];
  CHECK(format_progress(small, sizeof small, "sim", "frames", 120, 300, 3.0, false) == 11);
  CHECK(std::string(small) == "sim: 120/30");
}

TEST_CASE("progress writes nothing when its stream is a pipe, not a terminal") {
  int fds[2];
  REQUIRE(::pipe(fds) == 0);
  {
    Progress p("sim", "frames", 10, fds[1]);
    CHECK_FALSE(p.shown());
    for (long i = 0; i <= 10; ++i) p.update_at(i, 0.5 * static_cast<double>(i));
    p.clear();
    p.finish();
    CHECK(p.drawings() == 0);
  }
  ::close(fds[1]);
  char c;
  CHECK(::read(fds[0], &c, 1) == 0);  // end of file: not a byte was written
  ::close(fds[0]);
}

TEST_CASE("progress on a terminal: drawn in place, at most ten times a second, ended with a newline") {
  Pty pty;
  Progress p("sim", "frames", 300, pty.slave);
  REQUIRE(p.shown());
  p.update_at(0, 0.0);  // the first update draws
  CHECK(p.drawings() == 1);
  // 1000 updates over one second (a simulated tick each): ten more drawings, not a thousand.
  for (int ms = 1; ms <= 1000; ++ms) p.update_at(ms / 10, ms * 1e-3);
  CHECK(p.drawings() >= 10);
  CHECK(p.drawings() <= 11);
  const std::string drawn = pty.drain();
  CHECK(drawn.find('\n') == std::string::npos);  // one line, rewritten
  CHECK(drawn.find(" frames/s  0:0") != std::string::npos);  // about 100 frames/s, 2 s left
  CHECK(drawn.rfind("\rsim: 0/300 frames", 0) == 0);

  // clear() wipes the line (another message can go there); the next update draws it again.
  p.clear();
  const std::string wiped = pty.drain();
  CHECK(wiped.front() == '\r');
  CHECK(wiped.back() == '\r');
  CHECK(wiped.find_first_not_of(" \r") == std::string::npos);
  p.update_at(120, 1.01);
  CHECK(pty.drain().find("sim: 120/300 frames") != std::string::npos);

  p.finish(300);
  const std::string last = pty.drain();
  CHECK(last.find("sim: 300/300 frames") != std::string::npos);
  CHECK(last.find("taken") != std::string::npos);
  CHECK(last.back() == '\n');
  const int drawings = p.drawings();
  p.update_at(301, 5.0);  // after finish: nothing more
  p.finish();
  CHECK(p.drawings() == drawings);
  CHECK(pty.drain().empty());
}

TEST_CASE("progress on a terminal: a shorter line blanks the rest of the longer one before it") {
  Pty pty;
  Progress p("sim", "frames", 0, pty.slave);
  p.update_at(5, 1.0);     // "sim: 5 frames  5.00 frames/s"
  p.update_at(1000, 2.0);  // longer
  p.update_at(1001, 2000);  // "sim: 1001 frames  0.50 frames/s": shorter by a character
  const std::string text = pty.drain();
  const std::string last = text.substr(text.rfind('\r'));
  CHECK(last == "\rsim: 1001 frames  0.50 frames/s ");
}

TEST_CASE("progress that is never finished (a failed command) wipes its line instead of leaving it") {
  Pty pty;
  {
    Progress p("track", "frames", 40, pty.slave);
    p.update_at(3, 0.2);
    CHECK(pty.drain().find("track: 3/40 frames") != std::string::npos);
    Progress::clear_current();  // what fail() does before its message
    const std::string wiped = pty.drain();
    CHECK(wiped.size() > 2);
    CHECK(wiped.find_first_not_of(" \r") == std::string::npos);
  }
  CHECK(pty.drain().empty());  // nothing left to wipe, and no closing line
}

TEST_CASE("sim and track show their progress on a terminal and end it with a newline") {
  TempDir tmp("epichead_test_progress_tty");
  const std::string seq = tmp / "mockup_walk";
  const auto sim = run_with_stderr_on_pty(tmp, {"sim", "mockup_walk", "--out", seq, "--frames", "12"});
  INFO(sim.terminal);
  REQUIRE(sim.exit_code == 0);
  CHECK(sim.terminal.find("\rsim: ") != std::string::npos);
  CHECK(sim.terminal.find("sim: 12/12 frames") != std::string::npos);
  CHECK(sim.terminal.find("taken") != std::string::npos);
  CHECK(sim.terminal.back() == '\n');

  const auto track = run_with_stderr_on_pty(tmp, {"track", seq, "--out", tmp / "track", "--every", "0", "--no-video"});
  INFO(track.terminal);
  REQUIRE(track.exit_code == 0);
  CHECK(track.terminal.find("track: 12/12 frames") != std::string::npos);
  CHECK(track.terminal.back() == '\n');
}

TEST_CASE("sim-run and detection's template building show their progress on a terminal") {
  TempDir tmp("epichead_test_progress_tty_run");
  const auto sim_run = run_with_stderr_on_pty(tmp, {"sim-run", "mockup_walk", "--out", tmp / "run", "--seconds", "0.5", "--mode",
                                                    "stabilise", "--downscale", "8", "--every", "0", "--settle-s", "0"});
  INFO(sim_run.terminal);
  REQUIRE(sim_run.exit_code == 0);
  CHECK(sim_run.terminal.find("\rsim-run: ") != std::string::npos);
  CHECK(sim_run.terminal.find(" frames") != std::string::npos);
  CHECK(sim_run.terminal.find("taken") != std::string::npos);

  // Templates built afresh (no cache), on the coarsest view sphere to keep it short.
  const std::string seq = tmp / "mockup_walk";
  REQUIRE(run_epichead(tmp, "sim mockup_walk --out " + q(seq) + " --frames 1").exit_code == 0);
  const auto detect = run_with_stderr_on_pty(tmp, {"detect", seq, "--out", tmp / "det", "--views", "0", "--no-cache"});
  INFO(detect.terminal);
  CHECK(detect.terminal.find("epichead detect: building detection templates: ") != std::string::npos);
  CHECK(detect.terminal.find(" templates") != std::string::npos);
}

TEST_CASE("sim, track and sim-run write nothing on stderr when it is not a terminal") {
  TempDir tmp("epichead_test_progress_quiet");
  const std::string seq = tmp / "mockup_walk";
  const auto sim = run_epichead(tmp, "sim mockup_walk --out " + q(seq) + " --frames 12");
  REQUIRE(sim.exit_code == 0);
  CHECK(sim.err.empty());
  const auto track = run_epichead(tmp, "track " + q(seq) + " --out " + q(tmp / "track") + " --every 0 --no-video");
  REQUIRE(track.exit_code == 0);
  CHECK(track.err.empty());
  const auto sim_run = run_epichead(tmp, "sim-run mockup_walk --out " + q(tmp / "run") +
                                             " --seconds 0.5 --mode stabilise --downscale 8 --every 0 --settle-s 0");
  REQUIRE(sim_run.exit_code == 0);
  CHECK(sim_run.err.empty());
}

TEST_CASE("a command that fails on a terminal starts its message on a clean line") {
  TempDir tmp("epichead_test_progress_fail");
  const std::string seq = tmp / "mockup_walk";
  REQUIRE(run_epichead(tmp, "sim mockup_walk --out " + q(seq) + " --frames 4").exit_code == 0);
  // The third frame is garbled: track fails after its progress line was drawn.
  tmp.write("mockup_walk/frames/000002.png", "not a PNG");
  const auto track = run_with_stderr_on_pty(tmp, {"track", seq, "--out", tmp / "track", "--every", "0", "--no-video"});
  INFO(track.terminal);
  CHECK(track.exit_code == 1);
  const std::size_t message = track.terminal.find("epichead track: ");
  REQUIRE(message != std::string::npos);
  REQUIRE(message > 0);
  CHECK(track.terminal[message - 1] == '\r');  // the wiped line ends with a carriage return
}

TEST_CASE("tools/progress.sh: a progress line on a terminal, messages above it, nothing when stderr is a file") {
  TempDir tmp("epichead_test_progress_sh");
  const auto tty = run_on_pty(tmp, "/bin/bash", {"-c", kShellProgress});
  INFO(tty.terminal);
  REQUIRE(tty.exit_code == 0);
  CHECK(tty.terminal.find("\rdemo: 0/3 runs  0:0") != std::string::npos);
  CHECK(tty.terminal.find("demo: 1/3 runs  0:0") != std::string::npos);
  CHECK(tty.terminal.find(" left") != std::string::npos);
  CHECK(tty.terminal.find("demo: 3/3 runs  0:0") != std::string::npos);
  CHECK(tty.terminal.find(" taken") != std::string::npos);
  const std::string out = epichead::testing::slurp(tmp / "stdout.txt");
  CHECK(out == "demo: a message\nend\n");  // stdout gets the messages only

  const std::string err_path = tmp / "err.txt";
  const std::string command = "/bin/bash -c \"" + kShellProgress + "\" > '" + (tmp / "out.txt") + "' 2> '" + err_path + "'";
  REQUIRE(std::system(command.c_str()) == 0);
  CHECK(epichead::testing::slurp(err_path).empty());
  CHECK(epichead::testing::slurp(tmp / "out.txt") == "demo: a message\nend\n");
}
