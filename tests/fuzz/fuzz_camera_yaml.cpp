// camera.yaml through Camera::load (camera.h), OpenCV FileStorage underneath. Properties: a
// camera or a one-line error, never an exception, a crash or a huge allocation; a loaded
// camera has positive size and focal lengths and finite parameters; save() writes it so that
// load() reads back the same camera.
#include <cmath>
#include <string>

#include "epichead/vision/camera.h"
#include "fuzz_support.h"

using epichead::vision::Camera;
using epichead::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto& scratch = epichead::fuzz::Scratch::get();
  scratch.clear();
  const std::string path = scratch.write("camera.yaml", epichead::fuzz::as_text(data, size));
  std::expected<Camera, std::string> camera = std::unexpected(std::string());
  try {
    camera = Camera::load(path);
  } catch (const std::exception& e) {
    epichead::fuzz::fail(std::string("Camera::load threw: ") + e.what());
  }
  if (!camera) {
    epichead::fuzz::check_one_line(camera.error(), "Camera::load");
    return 0;
  }
  const auto& k = camera->intrinsics();
  check(camera->width_px() > 0 && camera->height_px() > 0, "a camera without pixels");
  check(k.fx_px > 0 && k.fy_px > 0 && std::isfinite(k.fx_px) && std::isfinite(k.fy_px) && std::isfinite(k.cx_px) &&
            std::isfinite(k.cy_px),
        "intrinsics not positive and finite");
  for (double d : camera->distortion()) check(std::isfinite(d), "a distortion coefficient is not finite");

  const std::string saved = (scratch.path() / "saved.yaml").string();
  const auto written = camera->save(saved);
  check(written.has_value(), "save failed: " + (written ? std::string() : written.error()));
  auto back = Camera::load(saved);
  check(back.has_value(), "a saved camera does not load: " + (back ? std::string() : back.error()));
  const auto& k2 = back->intrinsics();
  check(back->width_px() == camera->width_px() && back->height_px() == camera->height_px(), "image size changed");
  check(k2.fx_px == k.fx_px && k2.fy_px == k.fy_px && k2.cx_px == k.cx_px && k2.cy_px == k.cy_px, "intrinsics changed");
  check(back->distortion() == camera->distortion(), "distortion changed");
  return 0;
}
