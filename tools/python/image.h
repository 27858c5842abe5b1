#pragma once
// Images between numpy (uint8, HxW grey or HxWxC, C-contiguous) and cv::Mat.
#include <opencv2/core.hpp>

#include "bindings.h"

namespace epichead::python {

// A view of the array (no copy; valid while the array lives): HxW, HxWx1, HxWx3 (BGR) or HxWx4.
cv::Mat numpy_to_image(const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& a);
// A copy of an 8-bit image as a numpy array (HxW for one channel).
py::array_t<std::uint8_t> image_to_numpy(const cv::Mat& image);

}  // namespace epichead::python
