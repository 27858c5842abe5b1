// epichead.Tracker: the per-frame model tracker (vision/model_tracker.h) on numpy images, and
// FrameResult with the pose, status, covariance and the per-edge and per-circle results.
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/window_image.h"
#include "image.h"
#include "selected_lines.h"

namespace epichead::python {

using namespace epichead::vision;

cv::Mat numpy_to_image(const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& a) {
  const py::ssize_t channels = a.ndim() == 2 ? 1 : a.ndim() == 3 ? a.shape(2) : 0;
  if (channels != 1 && channels != 3 && channels != 4)
    throw Error("image: expected a uint8 array HxW (grey), HxWx3 (BGR) or HxWx4 (BGRA), got " + std::to_string(a.ndim()) +
                " dimensions" + (a.ndim() == 3 ? " with " + std::to_string(a.shape(2)) + " channels" : std::string()));
  if (a.shape(0) <= 0 || a.shape(1) <= 0) throw Error("image: empty");
  return cv::Mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_8UC(static_cast<int>(channels)),
                 const_cast<std::uint8_t*>(a.data()));
}

py::array_t<std::uint8_t> image_to_numpy(const cv::Mat& image) {
  if (image.depth() != CV_8U) throw Error("image: not 8-bit");
  const cv::Mat c = image.isContinuous() ? image : image.clone();
  std::vector<py::ssize_t> shape{c.rows, c.cols};
  if (c.channels() > 1) shape.push_back(c.channels());
  py::array_t<std::uint8_t> out(shape);
  std::memcpy(out.mutable_data(), c.data, c.total() * c.elemSize());
  return out;
}

namespace {

TrackMode parse_mode(const std::string& mode) {
  static const std::map<std::string, TrackMode> modes{
      {"gradient", TrackMode::Gradient}, {"epic", TrackMode::Epic}, {"epic+validation", TrackMode::EpicValidation}};
  const auto it = modes.find(mode);
  if (it == modes.end()) throw Error("mode must be gradient, epic or epic+validation, got '" + mode + "'");
  return it->second;
}

struct EllipseResult {
  int circle = -1;
  bool found = false, weak = false;
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double semi_major_px = 0, semi_minor_px = 0, angle_rad = 0;
  double arc_begin_rad = 0, arc_span_rad = 0;
  int support = 0;
};

struct FrameResult {
  FrameReport report;
  std::vector<tools::SelectedLine> lines;
  std::vector<EllipseResult> ellipses;
  std::vector<std::pair<int, Eigen::Vector2d>> junctions;
};

// The tracker, its model (the tracker keeps a pointer to it) and its image buffers.
class PyTracker {
 public:
  PyTracker(const Camera& camera, std::shared_ptr<const CadModel> model, const ModelTrackerOptions& options)
      : model_(std::move(model)), camera_(camera), tracker_(*model_, camera, options) {}

  FrameResult track(const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& image,
                    const Eigen::Matrix4d& pose, const std::optional<Eigen::Matrix4d>& fallback) {
    const cv::Mat frame = numpy_to_image(image);
    if (frame.cols != camera_.width_px() || frame.rows != camera_.height_px())
      throw Error("image: " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) + " but the camera is " +
                  std::to_string(camera_.width_px()) + "x" + std::to_string(camera_.height_px()));
    const Eigen::Isometry3d predicted = pose_from_matrix(pose, "pose");
    std::optional<Eigen::Isometry3d> second;
    if (fallback) second = pose_from_matrix(*fallback, "fallback");
    FrameResult r;
    {
      py::gil_scoped_release release;
      value_or_raise(image_.assign(frame));
      tracker_.track(image_, predicted, second ? &*second : nullptr, r.report);
      tools::selected_lines(tracker_, r.report, r.lines);
    }
    for (const EllipseFeature& e : tracker_.ellipses().features()) {
      if (!e.visible) continue;
      EllipseResult out;
      out.circle = e.circle;
      out.found = e.found;
      out.weak = e.weak;
      if (e.found) {
        out.centre_px = e.ellipse.centre_px;
        out.semi_major_px = e.ellipse.semi_major_px;
        out.semi_minor_px = e.ellipse.semi_minor_px;
        out.angle_rad = e.ellipse.angle_rad;
        out.arc_begin_rad = e.arc.begin_rad;
        out.arc_span_rad = e.arc.span_rad;
        out.support = e.inlier_count();
      }
      r.ellipses.push_back(out);
    }
    if (tracker_.options().mode == TrackMode::EpicValidation)
      for (const ValidatedJunction& j : tracker_.validation().junctions) r.junctions.emplace_back(j.vertex, j.px);
    return r;
  }
  void reset() { tracker_.reset(); }
  const ModelTracker& tracker() const { return tracker_; }

 private:
  std::shared_ptr<const CadModel> model_;
  Camera camera_;
  ModelTracker tracker_;
  WindowImage image_;
};

}  // namespace

void bind_tracker(py::module_& m) {
  py::class_<tools::SelectedLine>(m, "LineResult", "One visible model edge's outcome in a frame")
      .def_readonly("edge", &tools::SelectedLine::edge, "index into Model.edges")
      .def_readonly("candidates", &tools::SelectedLine::candidates, "candidate lines EPIC found in its window")
      .def_readonly("found", &tools::SelectedLine::found, "a candidate was chosen")
      .def_readonly("inlier", &tools::SelectedLine::inlier, "the pose kept it")
      .def_readonly("a_px", &tools::SelectedLine::a_px, "the chosen line's ends, pixels")
      .def_readonly("b_px", &tools::SelectedLine::b_px)
      .def_readonly("support", &tools::SelectedLine::support, "its inlier edgels")
      .def("__repr__", [](const tools::SelectedLine& l) {
        return "<epichead.LineResult edge " + std::to_string(l.edge) + (l.found ? l.inlier ? " kept>" : " rejected>" : " not found>");
      });
  py::class_<EllipseResult>(m, "EllipseResult", "One visible model circle's outcome in a frame")
      .def_readonly("circle", &EllipseResult::circle, "index into Model.circles")
      .def_readonly("found", &EllipseResult::found)
      .def_readonly("weak", &EllipseResult::weak, "found on an arc under 180 deg (unstable)")
      .def_readonly("centre_px", &EllipseResult::centre_px)
      .def_readonly("semi_major_px", &EllipseResult::semi_major_px)
      .def_readonly("semi_minor_px", &EllipseResult::semi_minor_px)
      .def_readonly("angle_rad", &EllipseResult::angle_rad)
      .def_readonly("arc_begin_rad", &EllipseResult::arc_begin_rad)
      .def_readonly("arc_span_rad", &EllipseResult::arc_span_rad)
      .def_readonly("support", &EllipseResult::support);
  py::class_<FrameResult>(m, "FrameResult", "What Tracker.track measured in one frame")
      .def_property_readonly("status", [](const FrameResult& r) { return to_string(r.report.status); },
                             "tracked, degraded or lost")
      .def_property_readonly("reasons", [](const FrameResult& r) { return to_string(r.report.reasons); },
                             "why not simply tracked, e.g. 'few_features+pose_failed' ('' when none)")
      .def_property_readonly("pose", [](const FrameResult& r) { return pose_matrix(r.report.cam_T_obj); },
                             "4x4 cam_T_obj (the prediction when lost)")
      .def_property_readonly("covariance", [](const FrameResult& r) { return Eigen::Matrix<double, 6, 6>(r.report.covariance); },
                             "6x6 covariance of the left perturbation (translation, rotation)")
      .def_property_readonly("pose_status", [](const FrameResult& r) { return to_string(r.report.pose_status); })
      .def_property_readonly("scale_px", [](const FrameResult& r) { return r.report.scale_px; })
      .def_property_readonly("visible", [](const FrameResult& r) { return r.report.visible; }, "line windows placed")
      .def_property_readonly("found", [](const FrameResult& r) { return r.report.found; })
      .def_property_readonly("inliers", [](const FrameResult& r) { return r.report.inliers; })
      .def_property_readonly("rejected", [](const FrameResult& r) { return r.report.rejected; })
      .def_property_readonly("used_fallback", [](const FrameResult& r) { return r.report.used_fallback; })
      .def_property_readonly(
          "start",
          [](const FrameResult& r) -> py::object {
            const StartSettle& s = r.report.start;
            if (!s.settled) return py::none();
            const auto support = [](const std::optional<double>& v) -> py::object {
              if (v) return py::float_(*v);
              return py::none();
            };
            return py::dict(py::arg("kept") = s.kept_gradient ? "gradient_pass" : "given",
                            py::arg("support_given") = support(s.support_given),
                            py::arg("support_gradient_pass") = support(s.support_gradient));
          },
          "on a start (the first frame, the first after a loss or reset()): which start the frame was measured from, "
          "'given' or 'gradient_pass', and the share of found features each measurement kept (None: unusable); "
          "None on other frames")
      .def_property_readonly("times_ms",
                             [](const FrameResult& r) {
                               const StageTimes& t = r.report.times;
                               return py::dict(py::arg("visibility") = t.visibility_ms, py::arg("epic") = t.epic_ms,
                                               py::arg("validation") = t.validation_ms, py::arg("pose") = t.pose_ms,
                                               py::arg("total") = t.total_ms);
                             })
      .def_readonly("lines", &FrameResult::lines, "a LineResult per visible model edge")
      .def_readonly("ellipses", &FrameResult::ellipses, "an EllipseResult per visible model circle")
      .def_readonly("junctions", &FrameResult::junctions, "(model vertex, pixel) of the validated junctions")
      .def("__repr__", [](const FrameResult& r) {
        return std::string("<epichead.FrameResult ") + to_string(r.report.status) + ", " + std::to_string(r.report.inliers) +
               " of " + std::to_string(r.report.visible) + " lines kept>";
      });

  py::class_<PyTracker>(m, "Tracker", "The EPIC model tracker (visibility, windows, cues, validation, robust pose)")
      .def(py::init([](const Camera& camera, std::shared_ptr<CadModel> model, const std::string& mode, double crease_deg,
                       double max_view_deg, bool free_turn, bool settle, bool outline_colours, std::uint32_t ransac_seed) {
             if (!model) throw Error("model: None");
             if (!(crease_deg >= 0 && crease_deg <= 180)) throw Error("crease_deg must be within 0 to 180");
             if (!(max_view_deg >= 0 && max_view_deg <= 90)) throw Error("max_view_deg must be within 0 to 90");
             ModelTrackerOptions o;
             o.mode = parse_mode(mode);
             o.visibility.crease_angle_rad = crease_deg * M_PI / 180.0;
             o.visibility.max_view_angle_rad = max_view_deg * M_PI / 180.0;
             o.free_turn_of_revolution = free_turn;
             o.settle = settle;
             o.outline_colours = outline_colours;
             o.lines.epic.ransac.seed = ransac_seed;
             return std::make_unique<PyTracker>(camera, std::move(model), o);
           }),
           py::arg("camera"), py::arg("model"), py::arg("mode") = "epic+validation", py::arg("crease_deg") = 20.0,
           py::arg("max_view_deg") = 85.0, py::arg("free_turn") = true, py::arg("settle") = true,
           py::arg("outline_colours") = true, py::arg("ransac_seed") = RansacOptions{}.seed,
           "The options are `epichead track`'s (--mode, --crease-deg, --max-view-deg, --free-turn, --no-settle, "
           "--no-outline-colours, --ransac-seed)")
      .def("track", &PyTracker::track, py::arg("image"), py::arg("pose"), py::arg("fallback") = py::none(),
           "Tracks one frame (uint8 HxW grey or HxWx3 BGR, the camera's size) from a given or predicted pose (4x4 "
           "cam_T_obj: the start pose on the first frame, then e.g. Predictor.predict(t_s).pose or the last pose). "
           "fallback: a second pose to measure from when nothing usable is found from the first")
      .def("reset", &PyTracker::reset, "Forgets every feature's references and history (re-initialisation)")
      .def_property_readonly("mode", [](const PyTracker& t) { return to_string(t.tracker().options().mode); })
      .def_property_readonly("free_turn_axis",
                             [](const PyTracker& t) -> py::object {
                               const auto& a = t.tracker().free_turn();
                               if (!a) return py::none();
                               return py::make_tuple(Eigen::Vector3d(a->point_obj), Eigen::Vector3d(a->direction_obj));
                             },
                             "(point, direction) of the body of revolution's axis whose turn the pose leaves free, or None");
}

}  // namespace epichead::python
