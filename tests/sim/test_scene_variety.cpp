// Scene variety: variety 0 is the built-in scene, a seed draws the same scene every time and
// another seed a different one, every draw keeps the object in view and visible, and a cover
// window hides the object completely.
#include <catch2/catch.hpp>

#include <filesystem>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "epichead/sim/rig.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/scene_library.h"
#include "epichead/sim/scene_variety.h"
#include "epichead/sim/sequence_writer.h"

using namespace epichead::sim;
namespace fs = std::filesystem;

namespace {

Scenario builtin(const std::string& name, std::uint64_t seed, double variety) {
  auto s = find_scenario(name);
  INFO(name << ": " << (s ? "" : s.error()));
  REQUIRE(s);
  s->seed = seed;
  s->variety = variety;
  return *s;
}

ScenarioScene made(const Scenario& s) {
  auto m = make_scenario_scene(s);
  INFO((m ? "" : m.error()));
  REQUIRE(m);
  return std::move(*m);
}

}  // namespace

TEST_CASE("variety 0 without covers gives the built-in scene and scenario unchanged", "[sim][scene_variety]") {
  for (const auto& name : {"mockup_walk", "lampshade", "box_clutter", "office_pan", "bowl"}) {
    CAPTURE(name);
    const Scenario s = builtin(name, 77, 0.0);
    const ScenarioScene m = made(s);
    auto nominal = make_scene(s.scene);
    REQUIRE(nominal);
    CHECK(m.scene.world_T_obj.isApprox(nominal->world_T_obj));
    CHECK(m.scene.light.direction_world == nominal->light.direction_world);
    CHECK(m.scene.light.ambient == nominal->light.ambient);
    CHECK(m.scene.textures.size() == nominal->textures.size());
    REQUIRE(m.scene.materials.size() == nominal->materials.size());
    for (std::size_t i = 0; i < m.scene.materials.size(); ++i)
      CHECK(m.scene.materials[i].albedo_bgr == nominal->materials[i].albedo_bgr);
    REQUIRE(m.scene.background.planes.size() == nominal->background.planes.size());
    for (std::size_t i = 0; i < m.scene.background.planes.size(); ++i)
      CHECK(m.scene.background.planes[i].texture == nominal->background.planes[i].texture);
    CHECK(m.scene.occluders.size() == nominal->occluders.size());
    CHECK(m.scenario.handheld.start_world == s.handheld.start_world);
    CHECK(m.scenario.walking.start_world == s.walking.start_world);
    CHECK(m.scenario.occluder_keys.size() == s.occluder_keys.size());
    CHECK(m.scenario.light.size() == s.light.size());
    CHECK(m.drawn.applied == 0);
  }
}

TEST_CASE("a seed draws the same scene every time, another seed a different one", "[sim][scene_variety]") {
  const ScenarioScene a = made(builtin("box_clutter", 11, 1.0));
  const ScenarioScene b = made(builtin("box_clutter", 11, 1.0));
  const ScenarioScene c = made(builtin("box_clutter", 12, 1.0));
  CHECK(to_json(a.drawn, "") == to_json(b.drawn, ""));
  CHECK(to_json(a.drawn, "") != to_json(c.drawn, ""));
  CHECK(a.drawn.light_azimuth_deg != c.drawn.light_azimuth_deg);
  CHECK(a.drawn.object_yaw_deg != c.drawn.object_yaw_deg);
  CHECK(a.drawn.start_world != c.drawn.start_world);
  CHECK(a.scene.world_T_obj.isApprox(b.scene.world_T_obj));
  CHECK_FALSE(a.scene.world_T_obj.isApprox(c.scene.world_T_obj));
  // Half the variety moves things half as far (same draw).
  const ScenarioScene h = made(builtin("box_clutter", 11, 0.5));
  if (h.drawn.attempt == 0 && a.drawn.attempt == 0) CHECK(h.drawn.object_yaw_deg == Approx(a.drawn.object_yaw_deg / 2));
  // The variety has its own random stream: the IMU and init streams are untouched, so the
  // trajectory seed is the only thing of the camera path that the variety sets.
  CHECK(a.scenario.imu.rate_hz == c.scenario.imu.rate_hz);
}

TEST_CASE("every drawn scene keeps the object in view in every frame and visible against its background",
          "[sim][scene_variety]") {
  // Three of the seeds 1-5 per scenario, a different three for the next: every seed is drawn
  // for several scenarios at three fifths of the time that all five for all would take.
  std::uint64_t first = 0;
  for (const auto& name : builtin_scenario_names()) {
    for (std::uint64_t seed : {first % 5 + 1, (first + 1) % 5 + 1, (first + 2) % 5 + 1}) {
      CAPTURE(name, seed);
      const ScenarioScene m = made(builtin(name, seed, 1.0));
      auto cam = scenario_camera(m.scenario);
      REQUIRE(cam);
      // In every frame where the built-in scene has it in view (late_entry and stumble take it
      // out on purpose).
      const ScenarioScene nominal = made(builtin(name, seed, 0.0));
      const auto in_view = frames_in_view(nominal.scenario, nominal.scene, *cam);
      CHECK(object_view_margin_px(m.scenario, m.scene, *cam, &in_view) >= kMinBorderPx);
      CHECK(m.drawn.min_border_px >= kMinBorderPx);
      CHECK(m.drawn.contrast >= std::min(0.15, m.drawn.builtin_contrast) - 1e-9);
      // A passing pole covers at most 30 % of the object's width.
      if (m.drawn.pole) CHECK(m.drawn.pole_diameter_m > 0);
      if (m.scenario.motion == MotionKind::walking) CHECK(m.scenario.walking.burst_s < m.scenario.walking.step_period_s);
    }
    ++first;
  }
}

TEST_CASE("a cover window hides the object completely and the board leaves afterwards", "[sim][scene_variety]") {
  // Two frames inside the window (the can at 6 s for 1 s) and two before the board comes.
  Scenario s = builtin("can", 5, 0.0);
  REQUIRE(s.covers.size() == 1);
  CHECK(s.covers[0].start_s == 6.0);
  CHECK(s.covers[0].duration_s == 1.0);
  const fs::path dir = fs::temp_directory_path() / "epichead_test_scene_variety";
  auto grey_dev = [&](double first_s) {
    Scenario t = s;
    t.first_frame_s = first_s;
    t.frames = 1;
    fs::remove_all(dir);
    auto ok = write_sequence(t, dir.string());
    INFO((ok ? "" : ok.error()));
    REQUIRE(ok);
    const cv::Mat img = cv::imread((dir / "frames" / "000000.png").string(), cv::IMREAD_GRAYSCALE);
    cv::Scalar mean, dev;
    cv::meanStdDev(img, mean, dev);
    return dev[0];
  };
  const double before = grey_dev(5.0), inside = grey_dev(6.5), after = grey_dev(7.8);
  CHECK(before > 20);
  CHECK(inside < 6);  // one board and sensor noise
  CHECK(after > 20);
  fs::remove_all(dir);
}

TEST_CASE("scenario keys: variety and cover are read, their errors name the file and line", "[sim][scenario]") {
  const std::string minimal = "scene can\nframes 10\nmotion handheld\n";
  auto s = parse_scenario(minimal + "variety 0.3\ncover 2 1\ncover 4.5 0.5\n", "t.scn");
  REQUIRE(s);
  CHECK(s->variety == 0.3);
  REQUIRE(s->covers.size() == 2);
  CHECK(s->covers[1].start_s == 4.5);
  CHECK(s->covers[1].duration_s == 0.5);
  auto d = parse_scenario(minimal, "t.scn");
  REQUIRE(d);
  CHECK(d->variety == 0);
  CHECK(d->covers.empty());
  auto error_of = [](const std::string& text, int line) {
    auto e = parse_scenario(text, "t.scn");
    REQUIRE(!e);
    CHECK(e.error().rfind("t.scn:" + std::to_string(line) + ": ", 0) == 0);
    return e.error();
  };
  CHECK(error_of(minimal + "variety 1.5\n", 4).find("out of range") != std::string::npos);
  CHECK(error_of(minimal + "cover 2\n", 4).find("takes 2 value(s)") != std::string::npos);
  CHECK(error_of(minimal + "cover x 1\n", 4).find("not a number") != std::string::npos);
  CHECK(error_of(minimal + "cover 2 1\ncover 2.5 1\n", 5).find("must not overlap") != std::string::npos);
}
