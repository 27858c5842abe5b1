#pragma once
// How well an image supports a projected model: the share of points sampled along the visible
// edges and ellipses that have an image edge of the same orientation close by. It verifies a
// detection hypothesis independently of the matcher that proposed it: LINE-2D scores a few
// dozen scattered features, this looks at the whole outline at the refined pose.
#include <opencv2/core.hpp>

#include "epichead/vision/visibility.h"

namespace epichead::vision::detail {

struct EdgeGradients {
  cv::Mat gx, gy;  // CV_16S Sobel 3x3 of the grey frame
  void compute(const cv::Mat& grey);
};

struct EdgeSupportOptions {
  double step_px = 3.0;          // between samples along an edge
  double radius_px = 2.0;        // searched either side of the projected edge, along its normal
  double min_gradient = 48.0;    // Sobel 3x3 magnitude (8x the grey levels per pixel)
  double max_angle_deg = 25.0;   // between the image gradient and the edge's normal
  int min_samples = 24;          // fewer: the model is too small to verify, support 0
};

struct EdgeSupport {
  long samples = 0, supported = 0;
  // Supported samples / samples (0 when there are fewer than min_samples).
  double share = 0;
};

// Samples every visible edge and ellipse.
EdgeSupport edge_support(const EdgeGradients& gradients, const VisibleModel& visible, const EdgeSupportOptions& options = {});

}  // namespace epichead::vision::detail
