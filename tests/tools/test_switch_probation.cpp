// Whether a recheck's switch stands (tools/switch_probation.h): undone when the filter started from
// the switched-to pose gates the first poses it judges, standing once it applies one or when
// nothing is judged for a while; frames the filter was not given do not count.
#include <catch2/catch.hpp>

#include "switch_probation.h"

using epichead::tools::ProbationOptions;
using epichead::tools::SwitchProbation;
using Decision = SwitchProbation::Decision;

namespace {
constexpr double kFrameS = 1.0 / 30;
}  // namespace

TEST_CASE("switch probation: three of the first four poses after a switch gated undo it, two applied let it stand") {
  SwitchProbation p;
  CHECK(p.judge(0.0, true, true) == Decision::None);  // no switch: nothing to judge
  p.begin(1.0);
  CHECK(p.active());
  CHECK(p.judge(1.0, false, false) == Decision::None);  // the switch's own frame starts the filter
  CHECK(p.judge(1.0 + kFrameS, true, true) == Decision::None);
  CHECK(p.judge(1.0 + 2 * kFrameS, true, true) == Decision::None);
  CHECK(p.judge(1.0 + 3 * kFrameS, true, true) == Decision::Undo);
  CHECK_FALSE(p.active());
  CHECK(p.judge(1.0 + 4 * kFrameS, true, true) == Decision::None);  // decided once

  p.begin(2.0);
  CHECK(p.judge(2.0 + kFrameS, true, true) == Decision::None);  // one gated pose, as after right switches
  CHECK(p.judge(2.0 + 2 * kFrameS, true, false) == Decision::None);
  CHECK(p.judge(2.0 + 3 * kFrameS, true, false) == Decision::Stands);  // two of four applied
  CHECK(p.judge(2.0 + 4 * kFrameS, true, true) == Decision::None);
  CHECK(p.judge(2.0 + 5 * kFrameS, true, true) == Decision::None);

  p.begin(3.0);  // one applied among the gated ones
  CHECK(p.judge(3.0 + kFrameS, true, true) == Decision::None);
  CHECK(p.judge(3.0 + 2 * kFrameS, true, true) == Decision::None);
  CHECK(p.judge(3.0 + 3 * kFrameS, true, false) == Decision::None);
  CHECK(p.judge(3.0 + 4 * kFrameS, true, true) == Decision::Undo);
}

TEST_CASE("switch probation: lost frames between do not count, a long wait lets the switch stand, a detection ends it") {
  SwitchProbation p;
  p.begin(1.0);
  CHECK(p.judge(1.0 + kFrameS, true, true) == Decision::None);
  CHECK(p.judge(1.0 + 2 * kFrameS, false, false) == Decision::None);  // lost: not given to the filter
  CHECK(p.judge(1.0 + 3 * kFrameS, true, true) == Decision::None);
  CHECK(p.judge(1.0 + 4 * kFrameS, true, true) == Decision::Undo);

  p.begin(2.0);
  CHECK(p.judge(2.0 + kFrameS, true, true) == Decision::None);
  CHECK(p.judge(2.4, false, false) == Decision::None);
  CHECK(p.judge(2.6, false, false) == Decision::Stands);  // over max_s (0.5 s) without a decision

  p.begin(3.0);
  CHECK(p.judge(3.0 + kFrameS, true, true) == Decision::None);
  p.end();
  CHECK_FALSE(p.active());
  CHECK(p.judge(3.0 + 2 * kFrameS, true, true) == Decision::None);
  CHECK(p.judge(3.0 + 3 * kFrameS, true, true) == Decision::None);
}

TEST_CASE("switch probation: gated_to_undo 0 or above judged lets every switch stand, 1 of 1 undoes at the first gated pose") {
  for (const int gated : {0, 5}) {
    SwitchProbation never(ProbationOptions{.judged = 4, .gated_to_undo = gated});
    never.begin(1.0);
    CHECK_FALSE(never.active());
    CHECK(never.judge(1.1, true, true) == Decision::None);
  }
  SwitchProbation strict(ProbationOptions{.judged = 1, .gated_to_undo = 1});
  strict.begin(1.0);
  CHECK(strict.judge(1.1, true, true) == Decision::Undo);
  strict.begin(2.0);
  CHECK(strict.judge(2.1, true, false) == Decision::Stands);
}
