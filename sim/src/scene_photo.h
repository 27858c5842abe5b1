#pragma once
// The scenes' photos (sim/scenes/*.jpg), decoded from the copies built into the program.
#include <expected>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

namespace epichead::sim {

// A built-in photo by file name ("board.jpg") as 8-bit BGR, the same pixels cv::imread gives
// for the file. Errors name the photo.
std::expected<cv::Mat, std::string> scene_photo(std::string_view file);

}  // namespace epichead::sim
