// When `epichead track` reruns detection on a frame it tracks (tools/recheck_schedule.h): for a
// while after a detected start or a doubtful frame (degraded, or re-locked after a loss), every
// interval; a detected pose's first recheck a tenth of a second after it, a doubtful frame's on
// that frame; lost frames never, and nothing when turned off.
#include <catch2/catch.hpp>

#include "recheck_schedule.h"

using epichead::tools::RecheckOptions;
using epichead::tools::RecheckSchedule;
using epichead::vision::TrackStatus;

namespace {

// The frames (at 30 Hz from t0_s for n frames, all with `status`) on which a recheck is due.
std::vector<int> due_frames(RecheckSchedule& s, TrackStatus status, double t0_s, int n) {
  std::vector<int> due;
  for (int i = 0; i < n; ++i)
    if (s.due_after(status, t0_s + i / 30.0)) due.push_back(i);
  return due;
}

}  // namespace

TEST_CASE("recheck schedule: a detected start is rechecked after a tenth of a second, then every half second for three seconds") {
  RecheckSchedule s;
  CHECK(due_frames(s, TrackStatus::Tracked, 0.0, 30).empty());  // nothing found yet
  s.found_at(1.0);
  CHECK(due_frames(s, TrackStatus::Tracked, 1.0, 120) == std::vector<int>{3, 18, 33, 48, 63, 78});
  CHECK(s.started_after_doubt() == 0);
  RecheckOptions even;
  even.first_recheck_s = even.recheck_interval_s;
  RecheckSchedule t(even);
  t.found_at(1.0);
  CHECK(due_frames(t, TrackStatus::Tracked, 1.0, 120) == std::vector<int>{15, 30, 45, 60, 75, 90});
}

TEST_CASE("recheck schedule: a degraded frame is rechecked at once and then as a detected start, lost frames never") {
  RecheckSchedule s;
  CHECK(s.due_after(TrackStatus::Degraded, 2.0));
  CHECK(s.started_after_doubt() == 1);
  CHECK_FALSE(s.due_after(TrackStatus::Degraded, 2.1));  // inside the stretch: no new start
  CHECK(s.started_after_doubt() == 1);
  CHECK_FALSE(s.due_after(TrackStatus::Lost, 2.5));
  CHECK(s.due_after(TrackStatus::Tracked, 2.51));
  CHECK(due_frames(s, TrackStatus::Tracked, 5.1, 60).empty());  // the stretch ended at 5 s
  CHECK(s.due_after(TrackStatus::Degraded, 6.0));  // a new one
  CHECK(s.started_after_doubt() == 2);
}

TEST_CASE("recheck schedule: a frame tracked again after a loss, from the prediction, is rechecked at once, as a degraded one") {
  // Without the IMU a burst leaves the tracker alternating between lost frames and locks on
  // clutter it reports as tracked; a lost run never reaches re-acquisition's count, so the
  // re-lock is the sign to look (box_clutter development seed 1: 89 -> 96 % of frames).
  RecheckSchedule s;
  CHECK_FALSE(s.due_after(TrackStatus::Tracked, 1.0));
  CHECK_FALSE(s.due_after(TrackStatus::Lost, 1.1));
  CHECK(s.due_after(TrackStatus::Tracked, 1.2, /*relocked=*/true));
  CHECK(s.started_after_doubt() == 1);
  CHECK_FALSE(s.due_after(TrackStatus::Tracked, 1.3, true));  // inside the stretch: on its schedule
  CHECK(s.due_after(TrackStatus::Tracked, 1.71));
  CHECK(s.started_after_doubt() == 1);
  RecheckOptions off;
  off.after_doubt = false;
  RecheckSchedule none(off);
  CHECK_FALSE(none.due_after(TrackStatus::Tracked, 1.2, true));
}

TEST_CASE("recheck schedule: the first frame kept after lost ones is a re-lock, whatever the tracker says") {
  // The tracker's re-locked frame was taken as lost (against gravity): the next one is the first
  // kept and carries no Reacquired (stumble development seed 3 with the IMU).
  RecheckSchedule s;
  CHECK_FALSE(s.due_after(TrackStatus::Tracked, 1.0));
  CHECK_FALSE(s.due_after(TrackStatus::Lost, 1.1));
  CHECK_FALSE(s.due_after(TrackStatus::Lost, 1.2));
  CHECK(s.due_after(TrackStatus::Tracked, 1.3));
  CHECK(s.started_after_doubt() == 1);
  CHECK_FALSE(s.due_after(TrackStatus::Tracked, 1.4));
  // A pose found by detection during the loss is provisional already: no stretch of its own.
  RecheckSchedule d;
  CHECK_FALSE(d.due_after(TrackStatus::Lost, 1.0));
  d.found_at(1.05);
  CHECK_FALSE(d.due_after(TrackStatus::Tracked, 1.1));
  CHECK(d.due_after(TrackStatus::Tracked, 1.16));  // the found pose's first recheck
  CHECK(d.started_after_doubt() == 0);
}

TEST_CASE("recheck schedule: off after doubtful frames, or with no provisional time, nothing is due") {
  RecheckOptions no_doubt;
  no_doubt.after_doubt = false;
  RecheckSchedule a(no_doubt);
  CHECK(due_frames(a, TrackStatus::Degraded, 0.0, 90).empty());
  RecheckOptions none;
  none.provisional_s = 0;
  RecheckSchedule b(none);
  b.found_at(0.0);
  CHECK(due_frames(b, TrackStatus::Degraded, 0.0, 90).empty());
}

TEST_CASE("recheck schedule: quiet ends the stretch's rechecks, and doubt within it starts none, until it is over") {
  RecheckSchedule s;
  s.found_at(1.0);
  CHECK(due_frames(s, TrackStatus::Tracked, 1.0, 4) == std::vector<int>{3});
  s.quiet();
  CHECK(due_frames(s, TrackStatus::Tracked, 1.2, 60).empty());
  CHECK_FALSE(s.due_after(TrackStatus::Degraded, 3.5));  // inside the stretch (until 4.0 s)
  CHECK(s.started_after_doubt() == 0);
  CHECK(s.due_after(TrackStatus::Degraded, 4.1));  // after it: a new stretch, rechecked at once
  s.found_at(5.0);  // a detection starts its own schedule
  CHECK(due_frames(s, TrackStatus::Tracked, 5.0, 4) == std::vector<int>{3});
}
