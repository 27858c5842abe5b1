#include "scene_photo.h"

#include <opencv2/imgcodecs.hpp>

#include "epichead/sim/builtin_asset.h"

namespace epichead::sim {

std::expected<cv::Mat, std::string> scene_photo(std::string_view file) {
  const std::string name = "scenes/" + std::string(file);
  const auto bytes = builtin_asset(name);
  if (!bytes) return std::unexpected(name + ": no such built-in photo");
  // cv::Mat has no constructor for const data; imdecode only reads it.
  const cv::Mat encoded(1, static_cast<int>(bytes->size()), CV_8UC1, const_cast<std::byte*>(bytes->data()));
  cv::Mat img = cv::imdecode(encoded, cv::IMREAD_COLOR);
  if (img.empty()) return std::unexpected(name + ": cannot decode the built-in photo");
  return img;
}

}  // namespace epichead::sim
