// Detection benchmarks (vision/detector.h), on a simulated 640x480 frame of the printed package
// on its cluttered table (box_clutter, frame 0):
//   detect_640x480       one global search with the default options, templates cached (built
//                        on the first run into the default cache, ~/.cache/epichead)
//   detect_near          re-acquisition's first try: the predicted pose refined and verified
//                        (here the true pose of the frame)
//   detect_build_teabox  building templates for the tea box (12 views, 30 deg turns: an
//   detect_build_300     iteration of the default 162 views and 15 deg turns would take tens of
//                        seconds), and for a model of 300 edges; per template in ns_per_item:
//                        the default options build 27x as many (162 views / 12, 24 turns / 12)
#include <memory>
#include <string>
#include <stdexcept>

#include "bench/bench.h"
#include "bench/box_models.h"
#include "bench/simulated_sequence.h"
#include "epichead/vision/detector.h"

namespace epichead::bench {
namespace {

struct DetectBench {
  std::unique_ptr<vision::Sequence> seq;
  cv::Mat frame;
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  std::unique_ptr<vision::Detector> detector;
  vision::DetectionResult result;
};

// box_clutter's first frame and its model, with the detector's templates (from the cache).
std::shared_ptr<DetectBench> box_clutter_frame() {
  SimulatedSequence sim = simulate_builtin("box_clutter", 1);
  auto b = std::make_shared<DetectBench>();
  b->seq = std::move(sim.seq);
  b->frame = sim.frames.front();
  b->truth = b->seq->ground_truth().front().cam_T_obj;
  auto detector = vision::Detector::create(b->seq->model(), b->seq->camera(), {}, {}, vision::default_template_cache_dir());
  if (!detector) throw std::runtime_error(detector.error());
  b->detector = std::move(*detector);
  return b;
}

const Registration detect_global{"detect_640x480", [] {
  auto b = box_clutter_frame();
  return [b] {
    auto r = b->detector->detect(b->frame);
    if (r) b->result = std::move(*r);
  };
}};

const Registration detect_near{"detect_near", [] {
  auto b = box_clutter_frame();
  vision::DetectionPrior prior;
  prior.near_cam_T_obj = b->truth;
  return [b, prior] {
    auto r = b->detector->detect(b->frame, prior);
    if (r) b->result = std::move(*r);
  };
}};

struct BuildBench {
  vision::CadModel model;
  vision::Camera camera{640, 480, {600, 600, 320, 240}};
  int templates = 0;
};

// Builds every template of the model (no cache) on the 12-view sphere with 30 deg turns, per
// iteration. The registration's item count is the number of templates (views of the model that
// fit in the image): checked here, so that ns_per_item is per template.
Iteration build_templates(std::shared_ptr<BuildBench> b, const char* name, int templates) {
  vision::DetectorOptions options;
  options.view_subdivisions = 0;
  options.in_plane_step_deg = 30;
  auto once = vision::Detector::create(b->model, b->camera, options, {}, "");
  if (!once) throw std::runtime_error(once.error());
  if ((*once)->template_count() != templates)
    throw std::runtime_error(std::string(name) + ": " + std::to_string((*once)->template_count()) +
                             " templates, but its registration counts " + std::to_string(templates));
  return [b, options] {
    auto detector = vision::Detector::create(b->model, b->camera, options, {}, "");
    if (!detector) throw std::runtime_error(detector.error());
    b->templates = (*detector)->template_count();
  };
}

constexpr int kTeaboxTemplates = 976, kGridTemplates = 982;

// The tea box with its camera.
const Registration build_teabox{"detect_build_teabox", [] {
  auto b = std::make_shared<BuildBench>();
  b->model = teabox_model();
  b->camera = vision::Camera(640, 480, {839.2147, 839.44555, 325.66776, 243.69727});
  return build_templates(b, "detect_build_teabox", kTeaboxTemplates);
}, kTeaboxTemplates};

const Registration build_300{"detect_build_300", [] {
  auto b = std::make_shared<BuildBench>();
  b->model = box_grid_300_model();
  return build_templates(b, "detect_build_300", kGridTemplates);
}, kGridTemplates};

}  // namespace
}  // namespace epichead::bench
