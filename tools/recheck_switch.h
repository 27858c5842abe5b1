#pragma once
// Whether a recheck's pose takes over from the tracked one (tools/track_acquisition.h). Both are
// scored on the same frame by the detector's verification (support x supported outline).
// - A pose that explains a much longer outline than the tracked one takes over at once
//   (switch_ratio).
// - A smaller lead takes over when two rechecks in a row found it (lasting_ratio). A wrong lock
//   on a box turned a quarter round about its long axis explains most of the outline too:
//   on stumble's development seed 6 the package's own pose scored 1.40-1.49x such a lock on six
//   rechecks in a row, and the lock was kept for the rest of the run. Where the tracked pose
//   was right, a pose found beside it scored at most 1.19x it on those seeds, but once 1.48x,
//   on a lone recheck.
// - Any lead takes over from a tracked pose that the detector itself would refuse (its
//   verification's tests, vision::failed_detection_tests), when the found pose passes them. A
//   short outline alone is no refusal here: it says the tracked object is small or partly out of
//   view, not that the pose is wrong, and a small outline's score is easily beaten by clutter's.
// No detection here: only the scores and times.
#include <cmath>

namespace epichead::tools {

struct SwitchOptions {
  double switch_ratio = 1.5;
  // <= switch_ratio; >= switch_ratio turns the lasting lead off.
  double lasting_ratio = 1.25;
  // Rechecks at most this far apart are "in a row" (the schedule's interval, with a frame's slack).
  double in_a_row_s = 0.6;
};

class RecheckSwitch {
 public:
  explicit RecheckSwitch(const SwitchOptions& options = {}) : options_(options) {}

  // A recheck at t_s: whether the found pose (found_score; nothing found: found false) takes
  // over from the tracked one (tracked_score; tracked_refused: it fails a test that says the
  // pose is wrong).
  bool take(double t_s, bool found, double found_score, double tracked_score, bool tracked_refused = false) {
    const bool leads = found && found_score >= options_.lasting_ratio * tracked_score;
    const bool lasting = leads && t_s - lead_t_s_ <= options_.in_a_row_s;
    lead_t_s_ = leads ? t_s : -INFINITY;
    const bool take = found && (found_score >= options_.switch_ratio * tracked_score || lasting ||
                                (tracked_refused && found_score > tracked_score));
    if (take) lead_t_s_ = -INFINITY;  // the next lead is over the pose taken
    return take;
  }
  // A pose found by detection outside a recheck (start, re-acquisition): earlier leads were over
  // another pose.
  void forget() { lead_t_s_ = -INFINITY; }

 private:
  SwitchOptions options_;
  double lead_t_s_ = -INFINITY;
};

}  // namespace epichead::tools
