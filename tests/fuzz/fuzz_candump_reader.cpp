// A whole candump log through CandumpReader (candump_reader.h), from memory and from a file.
// Properties: no crash; both paths see the same frames and the same malformed lines; counts
// add up (frames + malformed <= lines); kept errors are at most kKeptErrors and name a line
// within the file; the error handler sees every malformed line.
#include <cstring>
#include <string>
#include <vector>

#include "epichead/firmware_iface/candump_reader.h"
#include "fuzz_support.h"

using namespace epichead::firmware_iface;
using epichead::fuzz::check;

namespace {

struct Seen {
  std::vector<StampedCanFrame> frames;
  std::vector<std::string> ifaces;
  std::vector<std::uint64_t> error_lines;
  std::uint64_t lines = 0, malformed = 0;
};

Seen drain(CandumpReader& reader) {
  Seen s;
  reader.on_error([&s](const CandumpLineError& e) { s.error_lines.push_back(e.line); });
  CandumpRecord rec;
  while (reader.next(rec)) {
    s.frames.push_back(rec.frame);
    s.ifaces.emplace_back(rec.iface);
  }
  s.lines = reader.lines();
  s.malformed = reader.malformed();
  check(reader.frames() == s.frames.size(), "frames() disagrees with the frames returned");
  check(reader.malformed() == s.error_lines.size(), "the handler did not see every malformed line");
  check(reader.frames() + reader.malformed() <= reader.lines(), "more frames and errors than lines");
  check(reader.first_errors().size() <= CandumpReader::kKeptErrors, "kept too many errors");
  for (const auto& e : reader.first_errors()) {
    check(e.line >= 1 && e.line <= reader.lines(), "error on line " + std::to_string(e.line) + " of " +
                                                        std::to_string(reader.lines()));
    epichead::fuzz::check_one_line(e.message("fuzz.log"), "candump error");
  }
  return s;
}

bool same(const StampedCanFrame& a, const StampedCanFrame& b) {
  return a.stamp_us == b.stamp_us && a.frame.id == b.frame.id && a.frame.flags == b.frame.flags &&
         a.frame.len == b.frame.len && a.frame.data == b.frame.data;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(epichead::fuzz::as_text(data, size));
  CandumpReader memory = CandumpReader::from_memory(text);
  const Seen m = drain(memory);

  auto& scratch = epichead::fuzz::Scratch::get();
  scratch.clear();
  auto file = CandumpReader::open(scratch.write("fuzz.log", text));
  check(file.has_value(), "cannot open the written log");
  check(file->io_error().empty(), "I/O error: " + file->io_error());
  const Seen f = drain(*file);

  check(m.frames.size() == f.frames.size(), "memory and file readers disagree on the frame count");
  for (std::size_t i = 0; i < m.frames.size(); ++i) {
    check(same(m.frames[i], f.frames[i]) && m.ifaces[i] == f.ifaces[i],
          "memory and file readers disagree on frame " + std::to_string(i));
  }
  check(m.error_lines == f.error_lines, "memory and file readers disagree on the malformed lines");
  check(m.lines == f.lines, "memory and file readers disagree on the line count");
  return 0;
}
