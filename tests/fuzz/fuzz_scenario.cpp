// The simulator's scenario (.scn) reader (scenario.h). Properties: a scenario or a one-line
// error "name:line: what", never a crash, a hang or undefined behaviour (float-to-int casts of
// huge values included); a scenario has a positive frame count and frame rate and finite
// frame times. There is no scenario writer: Scenario::text keeps the file as read, and parsing
// that text again gives the same scenario.
#include <cmath>
#include <string>

#include "epichead/sim/scenario.h"
#include "fuzz_support.h"

using namespace epichead::sim;
using epichead::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(epichead::fuzz::as_text(data, size));
  const std::string name = "/nonexistent/fuzz.scn";
  auto s = parse_scenario(text, name);
  if (!s) {
    epichead::fuzz::check_one_line(s.error(), "parse_scenario");
    check(s.error().starts_with(name + ":"), "the error does not name the file: " + s.error());
    return 0;
  }
  check(s->frames > 0 && s->fps > 0 && std::isfinite(s->fps), "frames and fps must be positive");
  check(std::isfinite(s->frame_time_s(0)) && std::isfinite(s->frame_time_s(s->frames - 1)), "frame times not finite");
  auto again = parse_scenario(s->text, name);
  check(again.has_value(), "the scenario's own text does not parse again");
  check(again->frames == s->frames && again->fps == s->fps && again->scene == s->scene && again->seed == s->seed,
        "the scenario's own text parses to another scenario");
  return 0;
}
