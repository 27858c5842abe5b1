#pragma once
// Whether a recheck's switch (recheck_switch.h) stands, judged by the filter that restarted from
// the switched-to pose (with the IMU; tools/track_acquisition.h). The detector's verification
// scores the outline alone, and a pale object before a building's lines can lose to the model
// laid small on the facade: held-out mockup_walk 237 with the IMU, a switch to such a pose 3.5 m
// away at frame 17, and every pose tracked after it was gated (the facade does not move with the
// camera as an object there would), until the arbiter gave in to them six frames later. After
// the 19 other switches of the IMU runs read then (development 1-6 and held-out 237-239, three of
// them from a wrong lock to the object), at most one of the next four poses was gated
// (docs/detection.md, "A switch on probation").
// - Of the first `judged` poses the filter judges after the switch, gated_to_undo gated: undone
//   (the caller restores the filter as it was before the switch and measures the frame again). A
//   wrong switch's poses need not all be gated: with fewer detection views the same run switched
//   to a pose beside it, and the filter gated the 1st, 2nd and 4th pose after it and applied the 3rd.
// - Too many applied for that, or no decision within max_s: the switch stands.
// No detection and no filter here: only the verdicts and the times.
#include <cmath>

namespace epichead::tools {

struct ProbationOptions {
  int judged = 4;
  int gated_to_undo = 3;  // <= 0 or > judged: every switch stands at once
  double max_s = 0.5;     // the frames after a switch may be lost, not judged; then it stands
};

class SwitchProbation {
 public:
  enum class Decision { None, Stands, Undo };
  explicit SwitchProbation(const ProbationOptions& options = {}) : options_(options) {}

  // A switch at t_s: its poses are judged from now on.
  void begin(double t_s) {
    on_ = options_.gated_to_undo > 0 && options_.gated_to_undo <= options_.judged;
    since_s_ = t_s;
    gated_ = applied_ = 0;
  }
  // Another detection took over, or the filter was restarted otherwise: nothing left to judge.
  void end() { on_ = false; }
  bool active() const { return on_; }
  // The filter's verdict on the pose tracked at t_s (judged: it was given the pose and applied or
  // gated it; else the frame is not counted). Decision::None while undecided or inactive.
  Decision judge(double t_s, bool judged, bool gated) {
    if (!on_) return Decision::None;
    if (judged && gated && ++gated_ >= options_.gated_to_undo) return finish(Decision::Undo);
    if (judged && !gated && ++applied_ > options_.judged - options_.gated_to_undo) return finish(Decision::Stands);
    if (!(t_s - since_s_ <= options_.max_s)) return finish(Decision::Stands);
    return Decision::None;
  }

 private:
  Decision finish(Decision d) {
    on_ = false;
    return d;
  }
  ProbationOptions options_;
  bool on_ = false;
  double since_s_ = 0;
  int gated_ = 0, applied_ = 0;
};

}  // namespace epichead::tools
