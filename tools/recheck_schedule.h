#pragma once
// When `epichead track` runs the whole detection search on a frame it is tracking, to catch a
// wrong lock (tools/track_acquisition.h). A pose is provisional for provisional_s after it was
// found by detection, or after a degraded frame: every recheck_interval_s meanwhile the search
// runs again, and the caller switches to what it finds when that explains a much longer outline.
// A found pose's first recheck comes sooner: a start found while the object was still entering
// the view is as doubtful as a pose gets, and the frames after it show the object whole.
// So is a pose after a doubtful frame: a degraded one, or the first tracked again after a loss
// (re-locked from the prediction, not found by detection). Its first recheck is on that frame.
// No detection here: only the times.
#include <cmath>

#include "epichead/vision/model_tracker.h"

namespace epichead::tools {

struct RecheckOptions {
  double provisional_s = 3.0;        // <= 0: no rechecks at all
  double recheck_interval_s = 0.5;
  // After a pose found by detection, the first recheck this soon (then every interval).
  double first_recheck_s = 0.1;
  // A burst the constant-velocity prediction cannot follow, or with the IMU a jolt, a cover or a
  // bad first frame, leaves the tracker on a wrong lock that it then reports as tracked; the
  // degraded frames, or lost frames it then re-locks from, on the way there are the only sign, and
  // detection the only thing that tells the lock from the object.
  bool after_doubt = true;
};

class RecheckSchedule {
 public:
  explicit RecheckSchedule(const RecheckOptions& options = {}) : options_(options) {}

  // A pose found by detection at t_s: provisional from now, first recheck first_recheck_s later.
  void found_at(double t_s) {
    lost_before_ = false;
    provisional_until_s_ = t_s + options_.provisional_s;
    next_s_ = t_s + options_.first_recheck_s;
  }
  // After the tracker's frame at t_s (every frame, lost ones too): whether the search runs on it.
  // A doubtful frame (degraded, or re-locked: tracked again from the prediction after lost frames)
  // outside a provisional stretch starts one, with its first recheck on this frame; a lost frame
  // never rechecks (re-acquisition handles it). The first frame kept after lost ones counts as
  // re-locked whatever `relocked` (the tracker's Reacquired) says: when the tracker's re-locked
  // frame was then taken as lost (against gravity, the image's motion), the next one carries no
  // such reason (stumble development seed 3 with the IMU: re-locked 6-9 deg off after the jolt and
  // tracked for 24 frames unrechecked).
  bool due_after(vision::TrackStatus status, double t_s, bool relocked = false) {
    const bool after_loss = lost_before_;
    lost_before_ = status == vision::TrackStatus::Lost;
    relocked = relocked || after_loss;
    if (status == vision::TrackStatus::Lost || !(options_.provisional_s > 0)) return false;
    const bool doubtful = status == vision::TrackStatus::Degraded || relocked;
    if (doubtful && options_.after_doubt && !(t_s <= provisional_until_s_)) {
      ++after_doubt_;
      provisional_until_s_ = t_s + options_.provisional_s;
      next_s_ = t_s;
    }
    if (!(t_s <= provisional_until_s_ && t_s >= next_s_)) return false;
    next_s_ = t_s + options_.recheck_interval_s;
    return true;
  }
  // Whether t_s lies within a stretch (after a detection, or a doubtful frame that started one).
  bool provisional(double t_s) const { return t_s <= provisional_until_s_; }
  // No more rechecks in the stretch under way (a doubtful frame inside it starts none either).
  void quiet() { next_s_ = INFINITY; }
  int started_after_doubt() const { return after_doubt_; }

 private:
  RecheckOptions options_;
  double provisional_until_s_ = -INFINITY, next_s_ = 0;
  bool lost_before_ = false;  // the last frame was lost
  int after_doubt_ = 0;
};

}  // namespace epichead::tools
