#pragma once
// The picture a detection template is learnt from: the model's visible edges at a pose drawn
// as bright lines on black, with a mask of the object's projected area. Gradient orientation
// matching (LINE-2D) then sees the same edge directions the tracker will look for.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/vision/camera.h"
#include "epichead/vision/visibility.h"

namespace epichead::vision::detail {

struct EdgeDrawing {
  cv::Mat bgr;     // CV_8UC3, the crop around the object
  cv::Mat mask;    // CV_8UC1, same size: the object's projected area, a little dilated
  cv::Point origin{0, 0};  // the crop's top-left in the full image
  bool empty = true;       // nothing visible, or the object is not wholly inside the image
};

// Draws the visible edges (lines and ellipses) of `visible` into a crop of the camera's image.
// The object must lie wholly inside the image with `margin_px` to spare.
EdgeDrawing draw_edges(const VisibleModel& visible, const Camera& camera, int margin_px);

}  // namespace epichead::vision::detail
