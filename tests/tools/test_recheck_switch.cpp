// Whether a recheck's pose takes over from the tracked one (tools/recheck_switch.h): at once for a
// large lead, for a smaller one only when two rechecks in a row found it; a lead interrupted, too
// far apart, over a pose already taken, or before a start or re-acquisition does not count.
#include <catch2/catch.hpp>

#include "recheck_switch.h"

using epichead::tools::RecheckSwitch;
using epichead::tools::SwitchOptions;

TEST_CASE("recheck switch: a large lead takes over at once, a smaller one when it lasts two rechecks in a row") {
  RecheckSwitch s;
  CHECK(s.take(1.0, true, 300, 199));        // 1.51x
  CHECK_FALSE(s.take(1.5, true, 280, 200));  // 1.4x, the first time
  CHECK(s.take(2.0, true, 280, 200));        // and again
  CHECK_FALSE(s.take(2.5, true, 280, 200));  // the lead taken: a new one starts over
  CHECK(s.take(3.0, true, 250, 200));        // 1.25x after 1.4x
}

TEST_CASE("recheck switch: what breaks a lead: nothing found, a small lead, too long a gap, a detection between") {
  RecheckSwitch s;
  CHECK_FALSE(s.take(1.0, true, 280, 200));
  CHECK_FALSE(s.take(1.5, false, 400, 200));  // not found (its score does not count)
  CHECK_FALSE(s.take(2.0, true, 280, 200));
  CHECK_FALSE(s.take(2.5, true, 240, 200));   // 1.2x
  CHECK_FALSE(s.take(3.0, true, 280, 200));
  CHECK_FALSE(s.take(4.0, true, 280, 200));   // a second later: not in a row
  s.forget();                                 // a start or re-acquisition between
  CHECK_FALSE(s.take(4.5, true, 280, 200));
  CHECK(s.take(5.0, true, 280, 200));
}

TEST_CASE("recheck switch: a lasting ratio at the switch ratio turns the lasting lead off") {
  SwitchOptions o;
  o.lasting_ratio = o.switch_ratio;
  RecheckSwitch s(o);
  for (int i = 0; i < 5; ++i) CHECK_FALSE(s.take(1.0 + 0.5 * i, true, 290, 200));
  CHECK(s.take(4.0, true, 300, 200));
}

TEST_CASE("recheck switch: any lead takes over from a tracked pose the detector would refuse") {
  RecheckSwitch s;
  CHECK_FALSE(s.take(1.0, true, 210, 200));        // a small lead over a pose that passes
  CHECK(s.take(1.5, true, 210, 200, true));        // over one refused
  CHECK_FALSE(s.take(2.0, true, 190, 200, true));  // no lead
  CHECK_FALSE(s.take(2.5, false, 300, 200, true)); // nothing found
}
