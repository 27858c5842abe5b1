#pragma once
// Checks the text of a camera YAML before OpenCV's FileStorage parses it. OpenCV's YAML
// parser throws std::length_error (not cv::Exception) on an empty key in a flow mapping
// ("{ : 3 }"), and reads whatever it is given into memory: such text never reaches it.
#include <cstddef>
#include <expected>
#include <string>
#include <string_view>

namespace epichead::vision {

// A camera calibration is a few hundred bytes; anything this large is not one.
inline constexpr std::size_t kCameraYamlMaxBytes = std::size_t{1} << 20;

// Returns what is wrong ("line 3: empty key before ':'"), without the file name.
std::expected<void, std::string> precheck_camera_yaml(std::string_view text);

}  // namespace epichead::vision
