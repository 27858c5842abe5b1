// Benchmarks of the Kalman predictor (issue 7): imu_step (one 1 kHz sample: propagation of the
// state and its 17x17 covariance, stored in the ring), imu_step_unaided (a sample that also
// carries the unaided tilt update over 0.4 s of samples and the position hold, unaided_update.h;
// one in 200 does without vision), vision_update (a pose 100 ms late: the update at its exposure
// time and 100 samples of re-propagation) and carried_orientation_step (one gyro sample turning
// the orientation carried across a loss, fusion/carried_orientation.h, which the onboard loop adds
// to each sample). A still camera: the arithmetic per sample does not depend on the motion.
#include <memory>
#include <stdexcept>

#include "bench/bench.h"
#include "epichead/fusion/carried_orientation.h"
#include "epichead/fusion/predictor.h"
#include "epichead/geometry/so3.h"

namespace epichead::bench {
namespace {

using namespace epichead::fusion;

struct FusionBench {
  std::unique_ptr<Predictor> predictor;
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
  Matrix6d cov = Matrix6d::Identity();
  ImuSample sample;
  double t_s = 0;
  int rejected = 0;
};

// A predictor with 0.5 s of samples in its ring, initialised on the first pose.
std::shared_ptr<FusionBench> make_bench(const PredictorOptions& options = {}) {
  auto b = std::make_shared<FusionBench>();
  auto created = Predictor::create(options);
  if (!created) throw std::runtime_error(created.error());
  b->predictor = std::make_unique<Predictor>(std::move(*created));
  b->cam_T_obj.linear() = geometry::so3_exp(Eigen::Vector3d(0.2, -0.3, 0.1));
  b->cam_T_obj.translation() = Eigen::Vector3d(0.05, -0.02, 0.8);
  b->cov.diagonal() << 1e-6, 1e-6, 4e-6, 1e-5, 1e-5, 1e-5;
  // Still camera: the accelerometer reads -g in the camera frame (gravity along +y of the object).
  const Eigen::Vector3d g_obj(0, standard_gravity_mps2, 0);
  b->sample.gyro_radps = Eigen::Vector3d(1e-3, -2e-3, 5e-4);
  b->sample.accel_mps2 = -(b->cam_T_obj.linear() * g_obj);
  for (int k = 0; k < 600; ++k) {
    b->sample.t_s = b->t_s = k * 1e-3;
    b->predictor->add_imu(b->sample);
  }
  const auto r = b->predictor->add_vision(b->t_s - 0.2, b->cam_T_obj, b->cov);
  if (r.verdict != VisionVerdict::Initialised) throw std::runtime_error("fusion bench: no initialisation");
  return b;
}

const Registration imu_step{"imu_step", [] {
  auto b = make_bench();
  return [b] {
    b->t_s += 1e-3;
    b->sample.t_s = b->t_s;
    if (b->predictor->add_imu(b->sample) != ImuVerdict::Accepted) ++b->rejected;
  };
}};

// The down learnt from 40 poses at 30 Hz, then samples alone: from 0.2 s after the last pose
// every sample carries the unaided updates (period 1 ms here; 0.2 s by default, so on the robot
// one sample in 200 costs this much).
const Registration imu_step_unaided{"imu_step_unaided", [] {
  PredictorOptions options;
  options.unaided.period_s = 1e-3;
  auto b = make_bench(options);
  for (int pose = 0; pose < 40; ++pose) {
    for (int k = 0; k < 33; ++k) {
      b->t_s += 1e-3;
      b->sample.t_s = b->t_s;
      b->predictor->add_imu(b->sample);
    }
    if (b->predictor->add_vision(b->t_s - 0.01, b->cam_T_obj, b->cov).verdict != VisionVerdict::Applied) ++b->rejected;
  }
  if (!b->predictor->learnt_down_obj()) throw std::runtime_error("fusion bench: down not learnt");
  return [b] {
    b->t_s += 1e-3;
    b->sample.t_s = b->t_s;
    if (b->predictor->add_imu(b->sample) != ImuVerdict::Accepted) ++b->rejected;
  };
}};

// Each pose is 100 ms older than the newest sample (100 samples to re-propagate). Exposure times
// creep forward by 1 us per iteration so that every pose is newer than the last one applied; a
// new sample every 1000 iterations keeps the lag at 100 ms (0.4 ns per iteration on average).
const Registration vision_update{"vision_update", [] {
  auto b = make_bench();
  auto exposure_t_s = std::make_shared<double>(b->t_s - 0.1);
  return [b, exposure_t_s] {
    *exposure_t_s += 1e-6;
    while (b->t_s - *exposure_t_s < 0.1) {
      b->t_s += 1e-3;
      b->sample.t_s = b->t_s;
      if (b->predictor->add_imu(b->sample) != ImuVerdict::Accepted) ++b->rejected;
    }
    if (b->predictor->add_vision(*exposure_t_s, b->cam_T_obj, b->cov).verdict != VisionVerdict::Applied) ++b->rejected;
  };
}};

const Registration carried_orientation_step{"carried_orientation_step", [] {
  auto carried = std::make_shared<CarriedOrientation>(Eigen::Matrix3d::Identity(), CarriedOrientationNoise{});
  carried->set(0.0, geometry::so3_exp(Eigen::Vector3d(0.2, -0.3, 0.1)), 0.01, Eigen::Vector3d(1e-3, 0, 0));
  auto t_s = std::make_shared<double>(0.0);
  return [carried, t_s] {
    *t_s += 1e-3;
    carried->add_gyro(*t_s, Eigen::Vector3d(0.3, -0.2, 0.1));
  };
}};

}  // namespace
}  // namespace epichead::bench
