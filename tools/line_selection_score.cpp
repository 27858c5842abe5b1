#include "line_selection_score.h"

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "epichead/vision/visibility.h"

namespace epichead::tools {
namespace {

struct Selection {
  int edge = -1;
  bool found = false;
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();
};

double line_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = (b - a).normalized();
  const Eigen::Vector2d r = p - a;
  return std::abs(r.x() * d.y() - r.y() * d.x());
}

double angle_deg(const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
  const double c = std::abs(u.normalized().dot(v.normalized()));
  return std::acos(std::min(1.0, c)) * 180 / M_PI;
}

// Whether two projected segments overlap along the first one's direction.
bool overlap(const vision::VisibleEdge& e, const vision::VisibleEdge& o) {
  const Eigen::Vector2d d = (e.b_px - e.a_px).normalized();
  const double e0 = 0, e1 = (e.b_px - e.a_px).dot(d);
  double o0 = (o.a_px - e.a_px).dot(d), o1 = (o.b_px - e.a_px).dot(d);
  if (o0 > o1) std::swap(o0, o1);
  return o0 < e1 && o1 > e0;
}

}  // namespace

std::expected<LineSelectionScore, std::string> score_line_selection(const std::string& path, const vision::Sequence& seq,
                                                                    const std::vector<vision::StampedPose>& truth,
                                                                    const LineSelectionOptions& o) {
  std::ifstream in(path);
  if (!in) return std::unexpected(path + ": cannot open");
  std::map<int, std::vector<Selection>> by_frame;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) {
      if (line.rfind("frame,edge,found", 0) != 0) return std::unexpected(path + ": not a lines.csv (header 'frame,edge,found,...')");
      continue;
    }
    if (line.empty()) continue;
    std::istringstream row(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(row, cell, ',')) {
      char* end = nullptr;
      v.push_back(std::strtod(cell.c_str(), &end));
      if (end == cell.c_str() || !std::isfinite(v.back())) return std::unexpected(path + ":" + std::to_string(number) + ": bad number '" + cell + "'");
    }
    if (v.size() != 9) return std::unexpected(path + ":" + std::to_string(number) + ": expected 9 columns");
    by_frame[static_cast<int>(v[0])].push_back({static_cast<int>(v[1]), v[2] != 0, {v[4], v[5]}, {v[6], v[7]}});
  }

  LineSelectionScore s;
  vision::Visibility visibility(seq.model(), seq.camera());
  vision::VisibleModel vis;
  for (const vision::StampedPose& gt : truth) {
    const auto it = by_frame.find(gt.frame);
    if (it == by_frame.end()) continue;
    visibility.compute(gt.cam_T_obj, vis);
    std::map<int, const vision::VisibleEdge*> projected;
    for (const auto& e : vis.edges)
      if (e.kind != vision::EdgeKind::CylinderSilhouette && (e.b_px - e.a_px).norm() > 1.0) projected[e.edge] = &e;
    for (const Selection& sel : it->second) {
      const auto p = projected.find(sel.edge);
      if (p == projected.end()) continue;  // not visible at the true pose: nothing to judge
      if (!sel.found) {
        ++s.not_selected;
        continue;
      }
      const vision::VisibleEdge& e = *p->second;
      bool crowded = false;
      for (const auto& [id, other] : projected) {
        if (id == sel.edge) continue;
        const Eigen::Vector2d mid = 0.5 * (other->a_px + other->b_px);
        if (angle_deg(e.b_px - e.a_px, other->b_px - other->a_px) < o.crowded_angle_deg &&
            line_distance(mid, e.a_px, e.b_px) < o.crowded_distance_px && overlap(e, *other)) {
          crowded = true;
          break;
        }
      }
      const bool right = line_distance(sel.a, e.a_px, e.b_px) <= o.max_distance_px &&
                         line_distance(sel.b, e.a_px, e.b_px) <= o.max_distance_px &&
                         angle_deg(sel.b - sel.a, e.b_px - e.a_px) <= o.max_angle_deg;
      ++s.all.selections;
      s.all.right += right;
      if (crowded) {
        ++s.crowded.selections;
        s.crowded.right += right;
        LineSelectionCounts& f = s.crowded_by_frame[gt.frame];
        ++f.selections;
        f.right += right;
      }
    }
  }
  return s;
}

nlohmann::json to_json(const LineSelectionScore& s) {
  nlohmann::json by_frame = nlohmann::json::object();
  for (const auto& [frame, c] : s.crowded_by_frame) by_frame[std::to_string(frame)] = {c.right, c.selections};
  return {{"crowded_right_by_frame", by_frame},
          {"selections", s.all.selections},
          {"right_rate", s.all.rate()},
          {"crowded_selections", s.crowded.selections},
          {"crowded_right_rate", s.crowded.rate()},
          {"not_selected", s.not_selected}};
}

}  // namespace epichead::tools
