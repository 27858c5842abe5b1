#pragma once
// Who is wrong when vision and the filter disagree: the vision pose or the filter?
//
// The filter's gate alone says only that they disagree; after reinit_after_gated gated poses in a
// row the filter re-initialises from vision, whichever was wrong. The arbiter decides sooner, from
// what each side has for it, and restarts the filter from the vision pose, keeping the camera's
// motion the IMU measured (Predictor::restart_keeping_motion):
//   - fallback: the pose was measured from a second opinion (the vision poses extrapolated alone),
//     because nothing usable was found from the filter's prediction, and the image supports it
//     well: the prediction had left the object;
//   - supported-gated: three gated poses in a row that the image supports well (PoseSupport::strong):
//     the filter has drifted;
//   - agreeing-gated: gated poses that agree with each other (gated_agreement.h), applied ones
//     between them or not: the filter sits on a wrong lock that the tracker finds on some frames.
// Poses the image supports weakly never overrule the filter here; the filter's own
// reinit_after_gated does, once it is surely lost too (`track` sets it to half a second of frames).
//
// One arbiter per filter, given every vision pose the filter is given; `epichead track` and the
// onboard loop use it alike. It holds no reference to the filter, which the caller may replace
// (track's restart on an estimated clock offset): each call names it.
#include <cstdint>

#include <Eigen/Geometry>

#include "epichead/fusion/gated_agreement.h"
#include "epichead/fusion/predictor.h"

namespace epichead::fusion {

// What the image says for a vision pose, as the tracker reports it.
struct PoseSupport {
  bool strong = false;         // tracked, with nearly all found features kept and enough of them
  bool from_fallback = false;  // measured from the second opinion, not from the filter's prediction
};

enum class RestartReason : std::uint8_t { None, Fallback, SupportedGated, AgreeingGated };
// "fallback", "supported-gated", "agreeing-gated"; nullptr for None.
const char* to_string(RestartReason reason);

struct ArbitratedVision {
  VisionResult result;              // the pose's verdict on the filter as it was
  RestartReason restart = RestartReason::None;
  VisionResult after_restart;       // the pose's verdict on the restarted filter (restart != None)
  // The verdict that stands: after_restart when the filter restarted, else result.
  const VisionResult& final() const { return restart == RestartReason::None ? result : after_restart; }
};

struct ArbiterCounters {
  std::uint64_t fallback = 0, supported_gated = 0, agreeing_gated = 0;  // restarts, by reason
};

class VisionArbiter {
 public:
  // gate_chi2: the filter's gate (PredictorOptions::gate_chi2), at which gated poses agree.
  explicit VisionArbiter(double gate_chi2);
  // Gives the pose at its exposure time to `filter` and restarts the filter from it when the pose
  // overrules it. No allocation.
  ArbitratedVision add_vision(Predictor& filter, double exposure_t_s, const Eigen::Isometry3d& cam_T_obj,
                              const Matrix6d& cov, PoseSupport support);
  // The filter was reset or replaced from elsewhere (a loss, a detection): what was kept was
  // measured against the old state.
  void clear();
  const ArbiterCounters& counters() const { return counters_; }

 private:
  static constexpr int kSupportedGatedRestart = 3;
  GatedAgreement agreement_;
  int supported_gated_ = 0;  // strongly supported gated poses in a row
  ArbiterCounters counters_;
};

}  // namespace epichead::fusion
