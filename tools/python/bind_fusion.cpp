// epichead.Predictor: the buffered Kalman predictor (fusion/predictor.h) fed from Python.
#include <optional>
#include <string>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "epichead/fusion/predictor.h"

namespace epichead::python {

using namespace epichead::fusion;

namespace {

PredictorMode parse_mode(const std::string& mode) {
  if (mode == "imu") return PredictorMode::ImuAided;
  if (mode == "constant_velocity") return PredictorMode::ConstantVelocity;
  throw Error("mode must be 'imu' or 'constant_velocity', got '" + mode + "'");
}

py::dict counters_dict(const PredictorCounters& c) {
  return py::dict(py::arg("imu_accepted") = c.imu_accepted, py::arg("imu_buffered") = c.imu_buffered,
                  py::arg("imu_non_finite") = c.imu_non_finite, py::arg("imu_saturated") = c.imu_saturated,
                  py::arg("imu_out_of_order") = c.imu_out_of_order, py::arg("imu_duplicate") = c.imu_duplicate,
                  py::arg("imu_time_jump") = c.imu_time_jump, py::arg("imu_ignored") = c.imu_ignored,
                  py::arg("imu_restarts") = c.imu_restarts, py::arg("dropouts") = c.dropouts,
                  py::arg("dropout_total_s") = c.dropout_total_s, py::arg("vision_applied") = c.vision_applied,
                  py::arg("vision_initialised") = c.vision_initialised, py::arg("vision_gated") = c.vision_gated,
                  py::arg("vision_too_old") = c.vision_too_old, py::arg("vision_out_of_order") = c.vision_out_of_order,
                  py::arg("vision_bad_input") = c.vision_bad_input, py::arg("vision_no_imu") = c.vision_no_imu,
                  py::arg("vision_against_gravity") = c.vision_against_gravity,
                  py::arg("gravity_forgotten") = c.gravity_forgotten, py::arg("vision_unchecked") = c.vision_unchecked,
                  py::arg("unaided_down_updates") = c.unaided_down_updates,
                  py::arg("unaided_tilt_contradictions") = c.unaided_tilt_contradictions,
                  py::arg("unaided_position_holds") = c.unaided_position_holds,
                  py::arg("unaided_pose_floors") = c.unaided_pose_floors, py::arg("resumption_resets") = c.resumption_resets,
                  py::arg("reinitialisations") = c.reinitialisations,
                  py::arg("repropagated_samples") = c.repropagated_samples);
}

}  // namespace

void bind_fusion(py::module_& m) {
  py::class_<PosePrediction>(m, "Prediction", "A predicted pose for window placement")
      .def_readonly("t_s", &PosePrediction::t_s)
      .def_property_readonly("pose", [](const PosePrediction& p) { return pose_matrix(p.cam_T_obj); }, "4x4 cam_T_obj")
      .def_readonly("covariance", &PosePrediction::covariance, "6x6, left perturbation (translation, rotation)")
      .def_readonly("extrapolated_s", &PosePrediction::extrapolated_s, "time bridged without measurements");

  py::class_<Predictor>(m, "Predictor",
                        "The Kalman predictor: IMU samples (mode 'imu') or the vision poses alone ('constant_velocity'), "
                        "late vision poses applied at their exposure time, the pose predicted at any time")
      .def(py::init([](const std::string& mode, double imu_time_offset_s, double imu_rate_hz, double buffer_s,
                       const std::optional<Eigen::Matrix3d>& cam_R_imu, double imu_time_offset_sigma_s) {
             PredictorOptions o;
             o.mode = parse_mode(mode);
             o.imu_time_offset_s = imu_time_offset_s;
             o.imu_time_offset_sigma_s = imu_time_offset_sigma_s;
             o.imu_rate_hz = imu_rate_hz;
             o.buffer_s = buffer_s;
             if (cam_R_imu) o.mount.cam_R_imu = *cam_R_imu;
             return value_or_raise(Predictor::create(o));
           }),
           py::arg("mode") = "imu", py::arg("imu_time_offset_s") = 0.0, py::arg("imu_rate_hz") = 1000.0,
           py::arg("buffer_s") = 0.5, py::arg("cam_R_imu") = py::none(), py::arg("imu_time_offset_sigma_s") = 0.0,
           "imu_time_offset_s: how far the IMU clock runs ahead of the camera's (t_camera = t_imu - offset); "
           "imu_time_offset_sigma_s: how far that may be off (1-sigma, s), carried by each pose's covariance as "
           "its motion over that time")
      .def(
          "add_imu",
          [](Predictor& p, double t_s, const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel) {
            return std::string(to_string(p.add_imu({t_s, gyro, accel})));
          },
          py::arg("t_s"), py::arg("gyro_radps"), py::arg("accel_mps2"),
          "One IMU sample (device clock; IMU frame; specific force). Returns the verdict: accepted, buffered, or why "
          "it was rejected")
      .def(
          "add_vision",
          [](Predictor& p, double t_s, const Eigen::Matrix4d& pose, const Eigen::Matrix<double, 6, 6>& covariance) {
            const VisionResult r = p.add_vision(t_s, pose_from_matrix(pose, "pose"), covariance);
            return py::make_tuple(std::string(to_string(r.verdict)), r.mahalanobis2);
          },
          py::arg("exposure_t_s"), py::arg("pose"), py::arg("covariance"),
          "A vision pose (e.g. FrameResult.pose and .covariance) for the frame exposed at t_s (camera clock). "
          "Returns (verdict, squared Mahalanobis distance)")
      .def("predict", &Predictor::predict, py::arg("t_s"),
           "The Prediction at t_s (camera clock), or None before the first pose")
      .def(
          "status",
          [](const Predictor& p, double now_t_s) {
            const PredictorStatus s = p.status(now_t_s);
            return py::dict(py::arg("initialised") = s.initialised, py::arg("coasting") = s.coasting,
                            py::arg("newest_imu_t_s") = s.newest_imu_t_s, py::arg("last_update_t_s") = s.last_update_t_s,
                            py::arg("last_nis") = s.last_nis, py::arg("gated_in_a_row") = s.gated_in_a_row,
                            py::arg("counters") = counters_dict(s.counters));
          },
          py::arg("now_t_s"))
      .def("reset", &Predictor::reset, "Forgets the state (not the buffered samples): the next pose initialises again");
}

}  // namespace epichead::python
