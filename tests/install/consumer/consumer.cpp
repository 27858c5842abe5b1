// What a user's program does with an installed epichead: open a sequence, track its first
// frames from init.csv with the EPIC tracker, and check that the library's version is the
// package's. Prints one line per frame; exits 0 when every frame was tracked.
// Usage: consumer SEQUENCE_DIR [FRAMES]
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <string>
#include <string_view>

#include <epichead/firmware_iface/version.h>
#include <epichead/head/head_controller.h>
#include <epichead/vision/model_tracker.h>
#include <epichead/vision/offline/sequence.h>
#include <epichead/vision/window_image.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: consumer SEQUENCE_DIR [FRAMES]\n");
    return 2;
  }
#ifdef EXPECTED_VERSION
  // find_package's version (CMake) and the library's own must agree.
  if (epichead::firmware_iface::program_version() != std::string_view(EXPECTED_VERSION)) {
    std::fprintf(stderr, "consumer: library version %s, package version %s\n",
                 std::string(epichead::firmware_iface::program_version()).c_str(), EXPECTED_VERSION);
    return 1;
  }
#endif
  auto seq = epichead::vision::Sequence::open(argv[1]);
  if (!seq) {
    std::fprintf(stderr, "consumer: %s\n", seq.error().c_str());
    return 1;
  }
  const std::size_t frames = std::min<std::size_t>(argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 5, seq->frame_count());
  epichead::vision::ModelTracker tracker(seq->model(), seq->camera());
  epichead::vision::WindowImage window;
  epichead::vision::FrameReport report;
  Eigen::Isometry3d pose = seq->init().cam_T_obj;
  int tracked = 0;
  for (std::size_t i = 0; i < frames; ++i) {
    auto image = seq->read_frame(i);
    if (!image) {
      std::fprintf(stderr, "consumer: %s\n", image.error().c_str());
      return 1;
    }
    if (auto ok = window.assign(*image); !ok) {
      std::fprintf(stderr, "consumer: %s\n", ok.error().c_str());
      return 1;
    }
    tracker.track(window, pose, report);
    if (report.status != epichead::vision::TrackStatus::Lost) pose = report.cam_T_obj;
    tracked += report.status == epichead::vision::TrackStatus::Tracked;
    std::printf("frame %zu: %s, t = %.3f %.3f %.3f m\n", i, epichead::vision::to_string(report.status),
                pose.translation().x(), pose.translation().y(), pose.translation().z());
  }
  // A head controller with its defaults: the head's library and what it links (the bus, the devices).
  const epichead::head::HeadControllerOptions head_options;
  const auto controller = epichead::head::HeadController::create(head_options);
  if (!controller) {
    std::fprintf(stderr, "consumer: %s\n", controller.error().c_str());
    return 1;
  }
  std::printf("epichead %s: %d of %zu frames tracked; head controller at %.0f Hz\n",
              std::string(epichead::firmware_iface::program_version()).c_str(), tracked, frames, head_options.rate_hz);
  return tracked == static_cast<int>(frames) ? 0 : 1;
}
