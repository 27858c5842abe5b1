// epichead.Camera, Model, StampedPose, read/write_pose_csv, Sequence, score_poses.
#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/model_symmetry.h"
#include "epichead/vision/offline/score.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"
#include "image.h"

namespace epichead::python {

using namespace epichead::vision;
using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Points2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

namespace {

// A sequence and its model, shared with the trackers made from it (they keep a pointer to it).
struct PySequence {
  Sequence seq;
  std::shared_ptr<const CadModel> model;
};

LensModel parse_lens(const std::string& lens) {
  if (lens == "pinhole") return LensModel::Pinhole;
  if (lens == "fisheye") return LensModel::Fisheye;
  throw Error("lens must be 'pinhole' or 'fisheye', got '" + lens + "'");
}

// OpenCV's coefficient lists: 4, 5, 8, 12 or 14 values in its order, the rest zero.
Distortion parse_distortion(const std::vector<double>& values) {
  const std::size_t n = values.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    throw Error("distortion must have 4, 5, 8, 12 or 14 coefficients (OpenCV's order), got " + std::to_string(n));
  Distortion d{};
  std::copy(values.begin(), values.end(), d.begin());
  return d;
}

}  // namespace

void bind_vision(py::module_& m) {
  py::class_<Camera>(m, "Camera", "A calibrated camera (pinhole with OpenCV's 4 to 14 coefficients, or OpenCV's fisheye)")
      .def(py::init([](int width, int height, double fx, double fy, double cx, double cy, const std::vector<double>& d,
                       const std::string& lens) {
             return Camera(width, height, {fx, fy, cx, cy}, parse_distortion(d), parse_lens(lens));
           }),
           py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"),
           py::arg("distortion") = std::vector<double>{}, py::arg("lens") = "pinhole")
      .def_static("load", [](const std::string& path) { return value_or_raise(Camera::load(path)); }, py::arg("path"),
                  "Reads an OpenCV calibration YAML (or ROS camera_info.yaml)")
      .def("save", [](const Camera& c, const std::string& path) { value_or_raise(c.save(path)); }, py::arg("path"))
      .def_property_readonly("width", &Camera::width_px)
      .def_property_readonly("height", &Camera::height_px)
      .def_property_readonly("K", &Camera::K, "3x3 camera matrix")
      .def_property_readonly("distortion", &Camera::distortion, "14 values in OpenCV's order: k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tx ty (fisheye: k1..k4, then 0)")
      .def_property_readonly("lens", [](const Camera& c) { return c.lens() == LensModel::Fisheye ? "fisheye" : "pinhole"; })
      .def(
          "project",
          [](const Camera& c, const Points3& p_cam) {
            Points2 px(p_cam.rows(), 2);
            for (Eigen::Index i = 0; i < p_cam.rows(); ++i) px.row(i) = c.project(p_cam.row(i).transpose()).transpose();
            return px;
          },
          py::arg("points_cam"), "Nx3 camera-frame points (z > 0) -> Nx2 pixels")
      .def(
          "unproject",
          [](const Camera& c, const Points2& px) {
            Points3 rays(px.rows(), 3);
            for (Eigen::Index i = 0; i < px.rows(); ++i) rays.row(i) = c.unproject(px.row(i).transpose()).transpose();
            return rays;
          },
          py::arg("pixels"), "Nx2 pixels -> Nx3 ray directions with z = 1")
      .def("__repr__", [](const Camera& c) {
        return "<epichead.Camera " + std::to_string(c.width_px()) + "x" + std::to_string(c.height_px()) + ">";
      });

  py::class_<CadModel, std::shared_ptr<CadModel>>(m, "Model", "A CAD model read from a CAO file (ViSP's format)")
      .def_static("load", [](const std::string& path) { return std::make_shared<CadModel>(value_or_raise(load_cao(path))); },
                  py::arg("path"))
      .def_property_readonly("vertices",
                             [](const CadModel& c) {
                               Points3 v(static_cast<Eigen::Index>(c.vertices.size()), 3);
                               for (std::size_t i = 0; i < c.vertices.size(); ++i)
                                 v.row(static_cast<Eigen::Index>(i)) = c.vertices[i].transpose();
                               return v;
                             },
                             "Nx3 vertices, object frame, metres")
      .def_property_readonly("edges",
                             [](const CadModel& c) {
                               std::vector<std::pair<int, int>> e;
                               for (const ModelEdge& edge : c.edges) e.emplace_back(edge.v0, edge.v1);
                               return e;
                             },
                             "(v0, v1) per edge: the edge indices of FrameResult.lines")
      .def_property_readonly("faces",
                             [](const CadModel& c) {
                               std::vector<std::vector<int>> f;
                               for (const ModelFace& face : c.faces) f.push_back(face.vertices);
                               return f;
                             })
      .def_property_readonly("circles",
                             [](const CadModel& c) {
                               py::list l;
                               for (const ModelCircle& k : c.circles)
                                 l.append(py::dict(py::arg("centre") = Eigen::Vector3d(k.centre_obj),
                                                   py::arg("normal") = Eigen::Vector3d(k.normal_obj),
                                                   py::arg("radius") = k.radius_m));
                               return l;
                             })
      .def_readonly("closed", &CadModel::closed)
      .def_readonly("warnings", &CadModel::warnings)
      .def("__repr__", [](const CadModel& c) {
        return "<epichead.Model " + std::to_string(c.vertices.size()) + " vertices, " + std::to_string(c.edges.size()) +
               " edges, " + std::to_string(c.circles.size()) + " circles>";
      });

  py::class_<StampedPose>(m, "StampedPose", "A pose cam_T_obj at a frame and time (a row of init.csv, gt.csv, poses.csv)")
      .def(py::init([](int frame, double t_s, const Eigen::Matrix4d& pose, const std::string& status) {
             return StampedPose{frame, t_s, pose_from_matrix(pose, "StampedPose"), status};
           }),
           py::arg("frame"), py::arg("t_s"), py::arg("pose"), py::arg("status") = "")
      .def_readwrite("frame", &StampedPose::frame)
      .def_readwrite("t_s", &StampedPose::t_s)
      .def_property(
          "pose", [](const StampedPose& s) { return pose_matrix(s.cam_T_obj); },
          [](StampedPose& s, const Eigen::Matrix4d& p) { s.cam_T_obj = pose_from_matrix(p, "StampedPose.pose"); },
          "4x4 cam_T_obj")
      .def_readwrite("status", &StampedPose::status, "tracked, degraded, predicted, lost (poses.csv); empty elsewhere")
      .def("__repr__", [](const StampedPose& s) {
        return "<epichead.StampedPose frame " + std::to_string(s.frame) + (s.status.empty() ? "" : " " + s.status) + ">";
      });
  m.def("read_pose_csv", [](const std::string& path) { return value_or_raise(read_pose_csv(path)); }, py::arg("path"),
        "frame,t_s,tx,ty,tz,qw,qx,qy,qz[,status] -> list of StampedPose");
  m.def("write_pose_csv",
        [](const std::string& path, const std::vector<StampedPose>& poses) { value_or_raise(write_pose_csv(path, poses)); },
        py::arg("path"), py::arg("poses"));

  py::class_<FrameEntry>(m, "FrameEntry")
      .def_readonly("frame", &FrameEntry::frame)
      .def_readonly("t_s", &FrameEntry::t_s)
      .def_readonly("file", &FrameEntry::file);

  py::class_<PySequence>(m, "Sequence", "A sequence directory: camera, model, frames, init.csv, gt.csv, imu.csv")
      .def(py::init([](const std::string& dir) {
             auto seq = value_or_raise(Sequence::open(dir));
             auto model = std::make_shared<const CadModel>(seq.model());
             return std::make_unique<PySequence>(PySequence{std::move(seq), std::move(model)});
           }),
           py::arg("dir"))
      .def_property_readonly("dir", [](const PySequence& s) { return s.seq.dir(); })
      .def_property_readonly("camera", [](const PySequence& s) { return s.seq.camera(); })
      .def_property_readonly("model", [](const PySequence& s) { return std::const_pointer_cast<CadModel>(s.model); })
      .def_property_readonly("init", [](const PySequence& s) { return s.seq.has_init() ? py::cast(s.seq.init()) : py::none(); },
                             "The starting pose (init.csv), or None")
      .def_property_readonly("ground_truth", [](const PySequence& s) { return s.seq.ground_truth(); },
                             "gt.csv as a list of StampedPose (empty without it)")
      .def_property_readonly("imu",
                             [](const PySequence& s) {
                               Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> a(
                                   static_cast<Eigen::Index>(s.seq.imu().size()), 7);
                               for (std::size_t i = 0; i < s.seq.imu().size(); ++i) {
                                 const ImuRecord& r = s.seq.imu()[i];
                                 a.row(static_cast<Eigen::Index>(i)) << r.t_s, r.gyro_radps.transpose(), r.accel_mps2.transpose();
                               }
                               return a;
                             },
                             "imu.csv as an Nx7 array: t_s, gx, gy, gz (rad/s), ax, ay, az (m/s^2), camera frame")
      .def_property_readonly("frames", [](const PySequence& s) { return s.seq.frames(); })
      .def("__len__", [](const PySequence& s) { return s.seq.frame_count(); })
      .def(
          "read_frame",
          [](PySequence& s, std::size_t index) {
            if (index >= s.seq.frame_count())
              throw py::index_error(s.seq.dir() + ": frame index " + std::to_string(index) + " beyond its " +
                                    std::to_string(s.seq.frame_count()) + " frames");
            return image_to_numpy(value_or_raise(s.seq.read_frame(index)));
          },
          py::arg("index"), "Frame `index` (0-based position in frames) as a uint8 array, HxW or HxWx3 (BGR)");

  py::class_<ErrorStats>(m, "ErrorStats")
      .def_readonly("mean", &ErrorStats::mean)
      .def_readonly("median", &ErrorStats::median)
      .def_readonly("p95", &ErrorStats::p95)
      .def("__repr__", [](const ErrorStats& e) {
        return "<mean " + std::to_string(e.mean) + " median " + std::to_string(e.median) + " p95 " + std::to_string(e.p95) + ">";
      });
  py::class_<FrameScore>(m, "FrameScore")
      .def_readonly("frame", &FrameScore::frame)
      .def_readonly("present", &FrameScore::present)
      .def_readonly("success", &FrameScore::success)
      .def_readonly("success_2cm_2deg", &FrameScore::success_tight)
      .def_readonly("rotation_deg", &FrameScore::rotation_deg)
      .def_readonly("translation_mm", &FrameScore::translation_mm)
      .def_readonly("reprojection_px", &FrameScore::reprojection_px);
  py::class_<ScoreSummary>(m, "ScoreSummary", "What `epichead score` reports")
      .def_readonly("frames", &ScoreSummary::frames)
      .def_readonly("present", &ScoreSummary::present)
      .def_readonly("succeeded", &ScoreSummary::succeeded)
      .def_readonly("success_rate", &ScoreSummary::success_rate, "within 5 cm and 5 deg")
      .def_readonly("succeeded_2cm_2deg", &ScoreSummary::succeeded_tight)
      .def_readonly("success_rate_2cm_2deg", &ScoreSummary::success_rate_tight)
      .def_readonly("losses", &ScoreSummary::losses, "runs of failed frames")
      .def_readonly("rotation_deg", &ScoreSummary::rotation_deg)
      .def_readonly("translation_mm", &ScoreSummary::translation_mm)
      .def_readonly("reprojection_px", &ScoreSummary::reprojection_px)
      .def_readonly("per_frame", &ScoreSummary::per_frame);
  m.def(
      "score_poses",
      [](const std::vector<StampedPose>& truth, const std::vector<StampedPose>& estimates, const Camera& camera,
         const CadModel& model, std::optional<Eigen::Vector3d> sym_axis, bool symmetric) {
        if (sym_axis) {
          if (!sym_axis->allFinite() || sym_axis->norm() < 1e-9) throw Error("sym_axis must be a finite, non-zero axis");
          sym_axis->normalize();
        }
        const std::vector<Eigen::Isometry3d> symmetries = symmetric ? model_symmetries(model) : std::vector<Eigen::Isometry3d>{};
        return score_poses(truth, estimates, camera, model, sym_axis, {}, symmetries);
      },
      py::arg("ground_truth"), py::arg("estimates"), py::arg("camera"), py::arg("model"), py::arg("sym_axis") = py::none(),
      py::arg("symmetric") = false,
      "Scores estimates against ground truth frame by frame (as `epichead score`): a frame without an estimate, or "
      "lost, fails. sym_axis: the object's axis of symmetry (object frame); symmetric: up to the model's own symmetries");
}

}  // namespace epichead::python
