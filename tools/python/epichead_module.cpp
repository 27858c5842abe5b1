// `import epichead`: the camera, the CAO model, sequences, the tracker, the IMU predictor, the
// scorer and the CAN-log replay of the C++ libraries, for scripts (tools/python/README.md).
#include <cmath>
#include <string>

#include <pybind11/eigen.h>

#include "bindings.h"
#include "epichead/firmware_iface/version.h"

namespace epichead::python {

Eigen::Matrix4d pose_matrix(const Eigen::Isometry3d& pose) { return pose.matrix(); }

Eigen::Isometry3d pose_from_matrix(const Eigen::Matrix4d& m, const char* what) {
  if (!m.allFinite()) throw Error(std::string(what) + ": the pose holds NaN or infinity");
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-6 || r.determinant() < 0 ||
      (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
    throw Error(std::string(what) + ": not a rigid transform (a 4x4 matrix [R t; 0 0 0 1] with R a rotation)");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  pose.translation() = m.topRightCorner<3, 1>();
  return pose;
}

py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return py::str(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& v : j) l.append(to_python(v));
      return l;
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
      return d;
    }
    default: return py::none();  // binary, discarded: never in a report
  }
}

}  // namespace epichead::python

PYBIND11_MODULE(epichead, m) {
  namespace py = pybind11;
  using namespace epichead::python;
  m.doc() = "epichead: EPIC edge tracking of a CAD model, the IMU predictor, scoring and CAN-log replay "
            "(the C++ libraries; see tools/python/README.md). Poses are 4x4 numpy arrays cam_T_obj "
            "(X_cam = R X_obj + t), metres.";
  m.attr("__version__") = std::string(epichead::firmware_iface::program_version());
  py::register_exception<Error>(m, "Error", PyExc_ValueError);
  bind_vision(m);
  bind_tracker(m);
  bind_fusion(m);
  bind_replay(m);
}
