#pragma once
// Drawing of the visible model over an image, for the diagnostics written as PNG.
#include <opencv2/core.hpp>

#include "epichead/vision/visibility.h"

namespace epichead::vision {

// Colours of the overlay (BGR), one per ObjectSide so that the reader sees which side the
// tracker will look for the object on.
struct OverlayStyle {
  cv::Scalar left{80, 220, 80};     // object on the left of a->b: green
  cv::Scalar right{220, 80, 220};   // object on the right: magenta
  cv::Scalar both{60, 220, 240};    // object on both sides (crease): yellow
  cv::Scalar ellipse{255, 160, 40}; // projected circles: blue
  int thickness = 1;
  double tick_px = 6;               // length of the tick drawn toward the object side
};

// Draws every visible edge (with a tick toward the object side at its middle) and every
// projected circle onto `image` (8-bit, 1 or 3 channels; converted to BGR if grey).
void draw_visible_model(cv::Mat& image, const VisibleModel& visible, const OverlayStyle& style = {});

}  // namespace epichead::vision
