#include "epichead/vision/offline/overlay.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace epichead::vision {
namespace {

// Sub-pixel drawing: OpenCV takes fixed-point coordinates with `shift` fractional bits.
constexpr int kShift = 4;
cv::Point fixed(const Eigen::Vector2d& p) {
  return {static_cast<int>(std::lround(p.x() * (1 << kShift))), static_cast<int>(std::lround(p.y() * (1 << kShift)))};
}

}  // namespace

void draw_visible_model(cv::Mat& image, const VisibleModel& visible, const OverlayStyle& style) {
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  for (const VisibleEdge& e : visible.edges) {
    const cv::Scalar colour = e.side == ObjectSide::Left ? style.left : e.side == ObjectSide::Right ? style.right : style.both;
    cv::line(image, fixed(e.a_px), fixed(e.b_px), colour, style.thickness, cv::LINE_AA, kShift);
    const Eigen::Vector2d d = e.b_px - e.a_px;
    if (d.norm() < 1e-9 || e.side == ObjectSide::Both) continue;
    const Eigen::Vector2d left = Eigen::Vector2d(d.y(), -d.x()).normalized();
    const Eigen::Vector2d mid = 0.5 * (e.a_px + e.b_px);
    const double sign = e.side == ObjectSide::Left ? 1.0 : -1.0;
    cv::line(image, fixed(mid), fixed(mid + sign * style.tick_px * left), colour, style.thickness, cv::LINE_AA, kShift);
  }
  for (const VisibleEllipse& el : visible.ellipses) {
    const cv::RotatedRect box(cv::Point2f(static_cast<float>(el.centre_px.x()), static_cast<float>(el.centre_px.y())),
                              cv::Size2f(static_cast<float>(2 * el.semi_major_px), static_cast<float>(2 * el.semi_minor_px)),
                              static_cast<float>(el.angle_rad * 180 / M_PI));
    cv::ellipse(image, box, style.ellipse, style.thickness, cv::LINE_AA);
  }
}

}  // namespace epichead::vision
