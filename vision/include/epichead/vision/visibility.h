#pragma once
// Projection and visibility of a CAD model from a pose: the visible pieces of every edge
// (back-face culling, occlusion by other faces, near-plane and image clipping), which side of
// each projected edge the object is on, projected circles as ellipses, cylinder silhouettes.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/ellipse.h"

namespace epichead::vision {

// Where the object is relative to a projected edge a->b in the image (x right, y down):
// Left is the side of the normal (dy, -dx), i.e. on your left walking from a to b on screen.
enum class ObjectSide { Left, Right, Both };

enum class EdgeKind {
  Contour,             // between a face toward the camera and one away from it (silhouette)
  Crease,              // between two faces toward the camera, normals differ by > crease angle
  Boundary,            // the border of an open surface (one face)
  Wire,                // a free 3D line with no face
  CylinderSilhouette,  // a limb of a cylinder
};

// One visible piece of a model edge (an edge partly hidden yields several pieces).
struct VisibleEdge {
  int edge = -1;  // index into CadModel::edges, or into CadModel::cylinders for silhouettes
  EdgeKind kind = EdgeKind::Contour;
  ObjectSide side = ObjectSide::Both;
  Eigen::Vector3d a_obj, b_obj;  // the visible piece, object frame
  Eigen::Vector3d a_cam, b_cam;  // the same, camera frame
  Eigen::Vector2d a_px, b_px;    // projected end points (with distortion)
  double s0 = 0, s1 = 1;         // the piece as a fraction of the full model edge (a = v0 + s0 (v1 - v0))
};

// A model circle projected to an ellipse (pinhole, without distortion):
// p^T conic p = 0 for homogeneous pixel p.
struct VisibleEllipse {
  int circle = -1;  // index into CadModel::circles
  Eigen::Matrix3d conic_px = Eigen::Matrix3d::Zero();
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double semi_major_px = 0, semi_minor_px = 0;
  double angle_rad = 0;  // of the major axis from the image x axis
  bool facing_camera = true;  // the circle's normal points toward the camera
  // The part of the contour no face of the model hides, in polar angles about centre_px: the
  // far half of a can's bottom rim seen from above is behind the can, where tracker lines
  // would find only its print. Full when nothing hides it; a circle hidden all round is left
  // out of VisibleModel.
  EllipseArc seen;
  // Which side the object is on (Left = inside, as tracker-line columns run outward); set by
  // RimSides (rim_side.h), Both until then.
  ObjectSide side = ObjectSide::Both;
};

struct VisibilityOptions {
  // Edges between faces whose normals differ by less than this make no image edge (facets of
  // a curved surface) and are left out unless they lie on the silhouette.
  double crease_angle_rad = 20.0 * 3.14159265358979323846 / 180.0;
  double near_m = 0.01;        // near clipping plane
  double margin_px = 0;        // clip edges to the image shrunk by this margin
  double min_length_px = 2.0;  // visible pieces shorter than this are dropped
  // Across a sharp edge (faces further apart than the crease angle) of a closed model, a face
  // seen at a larger angle between its normal and the line of sight (to its nearest vertex)
  // counts as turned away: its far edges are not tracked and its near edges become contours.
  // Near edge-on a face projects to a sliver (at 85 deg, under a tenth of its width): the
  // windows of its two edges see the same image edge, and the far one pulls the pose. Like
  // ViSP's face appearance angle (which measures from the face's centre). 90 deg keeps every
  // front face; facets of smooth surfaces and open models always keep the strict test.
  double max_view_angle_rad = 85.0 * 3.14159265358979323846 / 180.0;
  // Clip circles by the model's faces (VisibleEllipse::seen; 48 occlusion tests per circle).
  // Off, every circle in front of the camera is seen whole: the detector's quick scores, which
  // sample whole ellipses anyway, run it thousands of times per frame.
  bool clip_circles = true;
};

struct VisibleModel {
  std::vector<VisibleEdge> edges;
  std::vector<VisibleEllipse> ellipses;
  void clear() { edges.clear(); ellipses.clear(); }
};

// Computes visibility for one model and camera. Holds its buffers, so repeated calls allocate
// nothing once `out` has grown to its working size.
class Visibility {
 public:
  Visibility(const CadModel& model, const Camera& camera, const VisibilityOptions& options = {});
  void compute(const Eigen::Isometry3d& cam_T_obj, VisibleModel& out);
  const VisibilityOptions& options() const { return options_; }

 private:
  // A segment to clip and emit: its ends in the camera and object frames, the faces it lies on
  // (not occluders of it; -1 for none), what it is, and the point that tells the object side.
  struct Segment {
    Eigen::Vector3d a_cam, b_cam, a_obj, b_obj;
    int face_a, face_b;
    int index;  // VisibleEdge::edge
    EdgeKind kind;
    Eigen::Vector3d side_probe_cam;
    bool side_from_probe;
  };
  // The stages of compute(), in order.
  void classify_faces(const Eigen::Vector3d& camera_obj);
  void place_occluders(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
  void add_edges(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, VisibleModel& out);
  void add_limbs(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& camera_obj, VisibleModel& out);
  void add_circles(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, VisibleModel& out);
  // Clipping of one segment: to the view, then by the occluders, then its visible pieces.
  bool clip_to_view(const Eigen::Vector3d& A, const Eigen::Vector3d& B, double& lo, double& hi) const;
  // depth_margin_m: a triangle hides only what lies further than this behind its plane.
  void find_hidden(const Segment& seg, double lo, double hi, const Eigen::Vector2d& n0, const Eigen::Vector2d& n1,
                   double depth_margin_m = 0);
  void emit_segment(const Segment& seg, VisibleModel& out);
  // The arc of a circle's image (centre c, in-plane unit axes u and v, camera frame) that the
  // occluders leave seen; false when they hide all of it.
  bool seen_arc(const ModelCircle& circle, const Eigen::Vector3d& c, const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                const Eigen::Vector2d& centre_px, EllipseArc& arc);

  const CadModel* model_;
  Camera camera_;
  VisibilityOptions options_;
  // Flat per-triangle data in the object frame, and per-call scratch in the camera frame.
  struct Triangle { Eigen::Vector3d p0, p1, p2; int face; };
  std::vector<Triangle> triangles_;
  std::vector<Eigen::Vector3d> vertices_cam_;
  std::vector<Eigen::Vector3d> tri_cam_;  // 3 per triangle
  // Per triangle, structure of arrays for a vectorised rejection test: bounding box in
  // normalised image coordinates (empty box = not an occluder this call).
  std::vector<float> tri_x0_, tri_x1_, tri_y0_, tri_y1_;
  std::vector<int> candidates_;  // scratch: triangles whose box meets the edge's
  std::vector<unsigned char> face_front_;  // the camera is on the face's outer side
  std::vector<unsigned char> face_seen_;   // ... and sees it within max_view_angle_rad (closed models)
  std::vector<std::pair<double, double>> hidden_;  // scratch intervals
  double xn_min_ = 0, xn_max_ = 0, yn_min_ = 0, yn_max_ = 0;  // image bounds, normalised
};

// Convenience: one call, plain values out.
VisibleModel compute_visibility(const CadModel& model, const Camera& camera,
                                const Eigen::Isometry3d& cam_T_obj,
                                const VisibilityOptions& options = {});

}  // namespace epichead::vision
