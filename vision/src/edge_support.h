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
  // Edges (and ellipses) with at least this many samples are judged one by one as well.
  int min_edge_samples = 8;
  double weak_edge_share = 0.25;  // an edge whose own support is below this is unsupported
};

struct EdgeSupport {
  long samples = 0, supported = 0;
  // Supported samples / samples (0 when there are fewer than min_samples).
  double share = 0;
  // Of the samples on edges long enough to judge alone, the share on edges whose own support
  // is below weak_edge_share; and the lowest own support of an edge judged alone (1 when none is).
  double unsupported_edge_share = 0;
  double weakest_edge_support = 1;
};

// Samples every visible edge and ellipse.
EdgeSupport edge_support(const EdgeGradients& gradients, const VisibleModel& visible, const EdgeSupportOptions& options = {});

// Does the outline run on past the object? Across a silhouette edge the object meets its
// background, and past its ends the background meets itself, so the colour difference across
// the edge's line drops there; a wire-frame laid on a grid of lines (a building's facade and
// windows, a tiled floor) finds it carrying on. Samples lie on the lines of the visible
// silhouette edges beyond their ends, up to reach_share of the edge's length (at most
// max_reach_px), outside the projected model's convex hull.
struct ContinuationOptions {
  double gap_px = 4.0;          // first sample this far past the end (corners mix two edges)
  double reach_share = 0.5;     // of the edge's length
  double max_reach_px = 40.0;
};
// Per end: the difference of mean colours on the two sides of the line past the end (strips
// 2-5 px off the line, both outside the hull) over the same difference along the edge itself
// (at least 10 levels). Returns the mean of these ratios (each capped at 2) and how many ends
// gave one. Textured clutter, whose edges are everywhere, differs little from one side of a
// line to the other over a strip, so the measure holds where edge counts do not.
struct ColourContinuation {
  double ratio = 0;
  int ends = 0;
};
ColourContinuation colour_continuation(const cv::Mat& bgr, const VisibleModel& visible, const ContinuationOptions& options = {});

}  // namespace epichead::vision::detail
