#include "epichead/fusion/vision_arbiter.h"

#include "epichead/geometry/se3.h"

namespace epichead::fusion {

const char* to_string(RestartReason reason) {
  switch (reason) {
    case RestartReason::None: return nullptr;
    case RestartReason::Fallback: return "fallback";
    case RestartReason::SupportedGated: return "supported-gated";
    case RestartReason::AgreeingGated: return "agreeing-gated";
  }
  return nullptr;
}

VisionArbiter::VisionArbiter(double gate_chi2) : agreement_(GatedAgreementOptions{.chi2 = gate_chi2}) {}

ArbitratedVision VisionArbiter::add_vision(Predictor& filter, double exposure_t_s, const Eigen::Isometry3d& cam_T_obj,
                                           const Matrix6d& cov, PoseSupport support) {
  ArbitratedVision out;
  // The filter's pose at the exposure before the update: a gated pose's innovation against it.
  const std::optional<PosePrediction> before = filter.predict(exposure_t_s);
  out.result = filter.add_vision(exposure_t_s, cam_T_obj, cov);
  const bool gated = out.result.verdict == VisionVerdict::Gated;
  if (gated && support.strong) ++supported_gated_;
  else supported_gated_ = 0;
  const bool agreeing = gated && before && agreement_.add(exposure_t_s, geometry::se3_log(cam_T_obj * before->cam_T_obj.inverse()), cov);
  if (support.from_fallback && support.strong) {
    out.restart = RestartReason::Fallback;
    ++counters_.fallback;
  } else if (supported_gated_ >= kSupportedGatedRestart) {
    out.restart = RestartReason::SupportedGated;
    ++counters_.supported_gated;
  } else if (agreeing) {
    out.restart = RestartReason::AgreeingGated;
    ++counters_.agreeing_gated;
  } else {
    return out;
  }
  out.after_restart = filter.restart_keeping_motion(exposure_t_s, cam_T_obj, cov);
  clear();
  return out;
}

void VisionArbiter::clear() {
  supported_gated_ = 0;
  agreement_.clear();
}

}  // namespace epichead::fusion
