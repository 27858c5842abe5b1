#include "edge_drawing.h"

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace epichead::vision::detail {

EdgeDrawing draw_edges(const VisibleModel& visible, const Camera& camera, int margin_px) {
  EdgeDrawing out;
  std::vector<cv::Point> points;
  for (const auto& e : visible.edges) {
    points.emplace_back(cvRound(e.a_px.x()), cvRound(e.a_px.y()));
    points.emplace_back(cvRound(e.b_px.x()), cvRound(e.b_px.y()));
  }
  std::vector<std::vector<cv::Point>> ellipses;
  for (const auto& el : visible.ellipses) {
    std::vector<cv::Point> poly;
    cv::ellipse2Poly(cv::Point(cvRound(el.centre_px.x()), cvRound(el.centre_px.y())),
                     cv::Size(cvRound(el.semi_major_px), cvRound(el.semi_minor_px)),
                     cvRound(el.angle_rad * 180.0 / M_PI), 0, 360, 5, poly);
    points.insert(points.end(), poly.begin(), poly.end());
    ellipses.push_back(std::move(poly));
  }
  if (points.size() < 3) return out;
  const cv::Rect box = cv::boundingRect(points);
  const cv::Rect image(0, 0, camera.width_px(), camera.height_px());
  const cv::Rect padded(box.x - margin_px, box.y - margin_px, box.width + 2 * margin_px, box.height + 2 * margin_px);
  if ((padded & image) != padded) return out;  // partly outside: a template must see the whole object

  out.origin = padded.tl();
  out.bgr = cv::Mat::zeros(padded.size(), CV_8UC3);
  out.mask = cv::Mat::zeros(padded.size(), CV_8UC1);
  const cv::Point o = out.origin;
  const cv::Scalar white(255, 255, 255);
  for (const auto& e : visible.edges)
    cv::line(out.bgr, cv::Point(cvRound(e.a_px.x()), cvRound(e.a_px.y())) - o,
             cv::Point(cvRound(e.b_px.x()), cvRound(e.b_px.y())) - o, white, 2, cv::LINE_8);
  for (auto poly : ellipses) {
    for (auto& p : poly) p -= o;
    cv::polylines(out.bgr, poly, true, white, 2, cv::LINE_8);
  }
  // The mask: the convex hull of everything drawn, grown so that the outer side of the
  // silhouette's gradient is inside it.
  std::vector<cv::Point> hull;
  for (auto& p : points) p -= o;
  cv::convexHull(points, hull);
  cv::fillConvexPoly(out.mask, hull, cv::Scalar(255));
  cv::dilate(out.mask, out.mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7)));
  out.empty = false;
  return out;
}

}  // namespace epichead::vision::detail
