// The closed-loop world through its ports, driven like the onboard loop drives it: every 1 ms
// advance the time, read the bus and the camera with timeout 0, send a HeadCommand.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <functional>
#include <numbers>
#include <vector>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/head_state.h"
#include "epichead/firmware_iface/head_status.h"
#include "epichead/firmware_iface/heartbeat.h"
#include "epichead/firmware_iface/time_sync.h"
#include "epichead/firmware_iface/imu_frames.h"
#include "epichead/firmware_iface/stamp_unwrap.h"
#include <opencv2/imgcodecs.hpp>

#include "common/temp_dir.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/sequence_writer.h"
#include "epichead/sim/sim_world.h"

using namespace epichead;
using namespace epichead::sim;
namespace fw = epichead::firmware_iface;

namespace {

// 30 frames of the walking robot before the mockup; the head aimed as in mockup_walk.
const std::string kBase =
    "scene mockup_walk\nframes 30\nmotion walking\nstart 0.30 -1.80 0.34\nheading_deg 98\naim 0 0.05 0.36\n";

Scenario scenario(const std::string& extra) {
  auto s = parse_scenario(kBase + extra, "test.scn");
  INFO((s ? "" : s.error()));
  REQUIRE(s);
  return *s;
}

std::unique_ptr<SimWorld> make_world(const Scenario& s, CameraOutput camera = CameraOutput::Blank) {
  SimWorldOptions o;
  o.camera = camera;
  o.camera_downscale = 8;
  auto w = SimWorld::create(s, o);
  INFO((w ? "" : w.error()));
  REQUIRE(w);
  return std::move(*w);
}

struct Received {
  std::int64_t stamp_us = 0;
  fw::CanFrame frame;
};
struct CameraRecord {
  std::uint64_t sequence = 0;
  double t_s = 0;
  std::uint64_t hash = 0;  // FNV-1a of the pixels
};
struct RunLog {
  std::vector<Received> frames;
  std::vector<double> bus_errors_s, send_failures_s;
  std::vector<CameraRecord> camera;
  std::vector<SimTruth> truth;  // one per tick
};

std::uint64_t fnv1a(const std::uint8_t* p, std::size_t n) {
  std::uint64_t h = 1469598103934665603ULL;
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ULL;
  return h;
}

// The command at t: Position mode; pan held, tilt swinging +-0.05 rad at 2 Hz (rate feed-forward).
using Commander = std::function<fw::HeadCommand(double t_s)>;
Commander swing(const HeadAngles& start) {
  return [start](double t) {
    const double w = 2 * std::numbers::pi * 2;
    fw::HeadCommand c;
    c.mode = fw::HeadMode::Position;
    c.pan_rad = start.pan_rad;
    c.tilt_rad = start.tilt_rad + 0.05 * std::sin(w * t);
    c.tilt_rate_radps = 0.05 * w * std::cos(w * t);
    return c;
  };
}

RunLog run_loop(SimWorld& world, double t_end_s, const Commander& commander) {
  RunLog log;
  REQUIRE(world.camera().start());
  std::uint8_t counter = 0;
  for (int k = 1; k * 1e-3 <= t_end_s + 1e-9; ++k) {
    const double t = k * 1e-3;
    REQUIRE(world.advance_to(t));
    REQUIRE(world.clock().now_s() == t);
    fw::StampedCanFrame f;
    for (;;) {
      const hw::CanReceive r = world.bus().receive(f, 0);
      if (r == hw::CanReceive::Frame) log.frames.push_back({f.stamp_us, f.frame});
      if (r == hw::CanReceive::Error) log.bus_errors_s.push_back(t);
      if (r != hw::CanReceive::Frame) break;
    }
    hw::CameraFrame image;
    while (world.camera().next_frame(image, 0) == hw::CameraRead::Frame)
      log.camera.push_back({image.sequence, image.t_s, fnv1a(image.data, image.size_bytes)});
    auto truth = world.truth_at(t);
    REQUIRE(truth);
    log.truth.push_back(*truth);
    fw::HeadCommand c = commander(t);
    c.counter = counter++ % 16;
    auto e = fw::encode(c);
    REQUIRE(e);
    if (!world.bus().send(e->frame)) log.send_failures_s.push_back(t);
  }
  return log;
}

HeadAngles start_angles(const SimWorld& w) {
  auto t = w.truth_at(0);
  REQUIRE(t);
  return t->joints;
}

// IMU gyro frames with their sample time. The frame's stamp wraps every 65.5 ms in 16 us steps:
// unwrapped with the receive time as the hint, and put back on the 1 ms device grid (the device
// clock is the true clock in these scenarios).
struct GyroSample {
  double t_s;
  std::int64_t receive_us;
  fw::ImuGyro gyro;
};
std::vector<GyroSample> gyro_samples(const RunLog& log) {
  std::vector<GyroSample> out;
  fw::StampUnwrapper unwrap(fw::kImuStampWrapUs);
  std::int64_t last_receive_us = -1;
  for (const Received& r : log.frames) {
    if (r.frame.id != fw::kIdImuGyro) continue;
    auto g = fw::decode_imu_gyro(r.frame);
    REQUIRE(g);
    const std::int64_t hint = last_receive_us < 0 ? -1 : r.stamp_us - last_receive_us;
    last_receive_us = r.stamp_us;
    const double stamp_s = static_cast<double>(unwrap.unwrap(g->stamp_mod_us, hint)) * 1e-6;
    out.push_back({std::round(stamp_s * 1e3) * 1e-3, r.stamp_us, *g});
  }
  return out;
}

}  // namespace

TEST_CASE("world: IMU frames decode to the true camera rate and specific force within the wire's resolution",
          "[sim][world]") {
  auto world = make_world(scenario("bus_jitter_us 0\n"));
  const RunLog log = run_loop(*world, 0.5, swing(start_angles(*world)));
  int gyro = 0, accel = 0;
  double max_rate = 0;
  int expected_counter = -1;
  for (const GyroSample& g : gyro_samples(log)) {
    // The frame arrives the bus latency after its sample.
    CHECK(static_cast<double>(g.receive_us) * 1e-6 - g.t_s == Approx(200e-6).margin(1e-6));
    auto truth = world->truth_at(g.t_s);
    REQUIRE(truth);
    for (int i = 0; i < 3; ++i) CHECK(std::abs(g.gyro.value[i] - truth->cam_rate_radps[i]) <= fw::kGyroRadpsPerLsb / 2 + 1e-9);
    max_rate = std::max(max_rate, truth->cam_rate_radps.norm());
    if (expected_counter >= 0) CHECK(g.gyro.counter == expected_counter);
    expected_counter = (g.gyro.counter + 1) % 16;
    ++gyro;
  }
  for (const Received& r : log.frames) {
    if (r.frame.id != fw::kIdImuAccel) continue;
    auto a = fw::decode_imu_accel(r.frame);
    REQUIRE(a);
    // Sampled on the 1 ms grid, 200 us before it arrived (the same time value the IMU used).
    auto truth = world->truth_at(static_cast<double>(std::llround((r.stamp_us - 200) / 1000.0)) * 1e-3);
    REQUIRE(truth);
    for (int i = 0; i < 3; ++i)
      CHECK(std::abs(a->value[i] - truth->cam_specific_force_mps2[i]) <= fw::kAccelMps2PerLsb / 2 + 1e-9);
    ++accel;
  }
  CHECK(gyro == 500);  // 1 kHz, samples at 1..500 ms (the 0 ms one arrived before the first read at 1 ms)
  CHECK(accel == gyro);
  CHECK(max_rate > 0.3);  // the swinging tilt moves the camera: the check above is not about a still camera
}

TEST_CASE("world: IMU noise from the scenario shows in the decoded frames at its density", "[sim][world]") {
  auto world = make_world(scenario("gyro_noise_radps_rthz 0.001\n"));
  const RunLog log = run_loop(*world, 0.6, swing(start_angles(*world)));
  double sum2 = 0;
  int n = 0;
  for (const GyroSample& s : gyro_samples(log)) {
    auto truth = world->truth_at(s.t_s);
    REQUIRE(truth);
    for (int i = 0; i < 3; ++i, ++n) sum2 += std::pow(s.gyro.value[i] - truth->cam_rate_radps[i], 2);
  }
  REQUIRE(n > 1500);
  const double sigma = 0.001 * std::sqrt(1000.0);
  CHECK(std::sqrt(sum2 / n) == Approx(sigma).epsilon(0.08));
}

TEST_CASE("world: the head follows HeadCommand frames after the command latency, HeadState reports it at 200 Hz",
          "[sim][world]") {
  auto world = make_world(scenario("command_latency_us 800\nhead_backlash_rad 0\nhead_accel_limit_radps2 100000\n"));
  const HeadAngles start = start_angles(*world);
  const RunLog log = run_loop(*world, 0.5, [start](double t) {
    fw::HeadCommand c;
    c.mode = fw::HeadMode::Position;
    c.pan_rad = start.pan_rad + (t >= 0.1 - 1e-9 ? 0.05 : 0.0);
    c.tilt_rad = start.tilt_rad;
    return c;
  });
  const auto pan_at = [&](double t) { return log.truth[static_cast<std::size_t>(std::lround(t * 1e3)) - 1].joints.pan_rad; };
  // Sent at 0.100 s, acted on from the first servo tick after 0.1008 s.
  CHECK(pan_at(0.100) == Approx(start.pan_rad).margin(1e-4));
  CHECK(pan_at(0.101) - start.pan_rad == Approx(0.0).margin(2e-4));
  CHECK(pan_at(0.102) - start.pan_rad > 5e-4);
  // First-order lag of 20 ms (the default time constant, below the rate limit).
  CHECK(pan_at(0.1208) - start.pan_rad == Approx(0.05 * (1 - std::exp(-1.0))).margin(0.002));
  CHECK(pan_at(0.5) - start.pan_rad == Approx(0.05).margin(1e-4));
  int states = 0;
  double last_pan = 0;
  for (const Received& r : log.frames) {
    if (r.frame.id != fw::kIdHeadState) continue;
    auto s = fw::decode_head_state(r.frame);
    REQUIRE(s);
    if (r.stamp_us > 2000) CHECK(s->mode == fw::HeadMode::Position);  // Off until the first command
    last_pan = s->pan_rad;
    ++states;
  }
  CHECK(states == Approx(100).margin(1));
  CHECK(last_pan == Approx(start.pan_rad + 0.05).margin(2e-4));
}

TEST_CASE("world: each injected fault acts inside its window and ends after it", "[sim][world][fault]") {
  auto world = make_world(
      scenario("fault imu_dropout 0.2 0.1\nfault bus_off 0.4 0.1\nfault camera_stall 0.6 0.2\n"
               "fault stuck_joint tilt 0.9 0.15\n"));
  const RunLog log = run_loop(*world, 1.2, swing(start_angles(*world)));

  SECTION("imu_dropout: no samples from 0.2 s to 0.3 s, samples before and after") {
    // (The samples at exactly 0.2 s and 0.3 s sit on the window's edges: not counted.)
    int before = 0, inside = 0, after = 0;
    for (const GyroSample& s : gyro_samples(log)) {
      before += s.t_s > 0.1005 && s.t_s < 0.1995;
      inside += s.t_s > 0.2005 && s.t_s < 0.2995;
      after += s.t_s > 0.3005 && s.t_s < 0.3995;
    }
    CHECK(before == 99);
    CHECK(inside == 0);
    CHECK(after == 99);
    CHECK(world->imu_node().counters().lost_fault >= 99);
    CHECK(world->imu_node().counters().lost_fault <= 101);
  }
  SECTION("bus_off: receive errors and failed sends exactly from 0.4 s to 0.5 s, frames again after") {
    REQUIRE(!log.bus_errors_s.empty());
    CHECK(log.bus_errors_s.front() == Approx(0.4));
    CHECK(log.bus_errors_s.back() == Approx(0.499));
    CHECK(log.bus_errors_s.size() == 100);
    CHECK(log.send_failures_s == log.bus_errors_s);
    int after = 0;
    for (const Received& r : log.frames) after += r.stamp_us >= 500000 && r.stamp_us < 600000;
    CHECK(after > 200);
    CHECK(world->bus().stats().state == hw::CanBusState::ErrorActive);
    CHECK(world->bus().stats().bus_off_events == 1);
    CHECK(world->sim_bus().counters().lost_bus_off > 200);
  }
  SECTION("camera_stall: frames exposed from 0.6 s to 0.8 s never arrive; the sequence jumps") {
    std::vector<std::uint64_t> seen;
    for (const CameraRecord& c : log.camera) seen.push_back(c.sequence);
    // Exposure start = 0.2 s + i / 30 - 4 ms: frames 13..18 start inside the window.
    for (std::uint64_t i = 0; i < seen.size(); ++i) INFO(seen[i]);
    std::vector<std::uint64_t> expected;
    for (std::uint64_t i = 0; i <= 29; ++i) {
      const double ready = 0.2 + static_cast<double>(i) / 30 + 0.004 + 0.010;
      if (ready <= 1.2 && (i < 13 || i > 18)) expected.push_back(i);
    }
    CHECK(seen == expected);
    CHECK(world->camera().stats().dropped_frames == 6);
    CHECK(world->sim_camera().frames_stalled() == 6);
  }
  SECTION("stuck_joint tilt: the tilt stops from 0.9 s to 1.05 s with over-current, then moves again") {
    const auto tilt_at = [&](double t) {
      return log.truth[static_cast<std::size_t>(std::lround(t * 1e3)) - 1].joints.tilt_rad;
    };
    CHECK(tilt_at(0.85) != Approx(tilt_at(0.89)).margin(1e-3));
    CHECK(tilt_at(0.91) == tilt_at(1.04));
    CHECK(tilt_at(1.1) != Approx(tilt_at(1.04)).margin(1e-3));
    int over_current_inside = 0, over_current_outside = 0;
    for (const Received& r : log.frames) {
      if (r.frame.id != fw::kIdHeadStatus) continue;
      auto s = fw::decode_head_status(r.frame);
      REQUIRE(s);
      const bool bit = (s->faults & fw::kFaultTiltOverCurrent) != 0;
      const double t = static_cast<double>(r.stamp_us) * 1e-6;
      if (t >= 0.9 && t < 1.051) over_current_inside += bit;
      else over_current_outside += bit;
    }
    CHECK(over_current_inside >= 6);
    CHECK(over_current_outside == 0);
  }
}

TEST_CASE("world: a closed-loop run is deterministic for a seed (bus bytes, stamps and images)", "[sim][world]") {
  const Scenario s = scenario(
      "seed 11\nbus_jitter_us 150\nbus_drop_rate 0.01\ngyro_noise_radps_rthz 0.0003\naccel_noise_mps2_rthz 0.002\n"
      "gyro_bias_radps 0.002\nimu_dropouts 1 0.01\nfault bus_off 0.3 0.05\nantialias 1\n");
  const auto run = [&s] {
    auto world = make_world(s, CameraOutput::Render);
    return run_loop(*world, 0.5, swing(start_angles(*world)));
  };
  const RunLog a = run(), b = run();
  REQUIRE(a.frames.size() == b.frames.size());
  REQUIRE(a.frames.size() > 1000);
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    CHECK(a.frames[i].stamp_us == b.frames[i].stamp_us);
    CHECK(a.frames[i].frame.id == b.frames[i].frame.id);
    CHECK(std::memcmp(a.frames[i].frame.data.data(), b.frames[i].frame.data.data(), 8) == 0);
  }
  REQUIRE(a.camera.size() == b.camera.size());
  REQUIRE(a.camera.size() >= 8);
  for (std::size_t i = 0; i < a.camera.size(); ++i) CHECK(a.camera[i].hash == b.camera[i].hash);
  // A different seed changes the bytes (the check above can fail).
  Scenario other = s;
  other.seed = 12;
  auto world = make_world(other, CameraOutput::Render);
  const RunLog c = run_loop(*world, 0.5, swing(start_angles(*world)));
  bool differs = c.frames.size() != a.frames.size();
  for (std::size_t i = 0; !differs && i < a.frames.size(); ++i)
    differs = std::memcmp(a.frames[i].frame.data.data(), c.frames[i].frame.data.data(), 8) != 0;
  CHECK(differs);
}

TEST_CASE("world: time only moves forward, within the horizon, truth only within its history", "[sim][world]") {
  auto world = make_world(scenario(""));
  REQUIRE(world->advance_to(0.5));
  auto back = world->advance_to(0.4);
  REQUIRE(!back);
  CHECK(back.error().find("cannot go back") != std::string::npos);
  CHECK(!world->advance_to(std::nan("")));
  auto far = world->advance_to(world->horizon_s() + 1);
  REQUIRE(!far);
  CHECK(far.error().find("horizon") != std::string::npos);
  CHECK(world->now_s() == 0.5);
  CHECK(!world->truth_at(0.6));
  CHECK(world->truth_at(0.5));
  REQUIRE(world->advance_to(1.7));
  CHECK(!world->truth_at(0.5));
  // A receive that waits moves the world's time by the wait.
  fw::StampedCanFrame f;
  while (world->bus().receive(f, 0) == hw::CanReceive::Frame) {
  }
  CHECK(world->bus().receive(f, 0.01) == hw::CanReceive::Frame);
  CHECK(world->now_s() > 1.7);
  CHECK(world->now_s() <= 1.71);

  SimWorldOptions bad;
  bad.camera_downscale = 3;
  auto w = SimWorld::create(scenario(""), bad);
  REQUIRE(!w);
  CHECK(w.error().find("camera_downscale") != std::string::npos);
}

TEST_CASE("world: both nodes answer a time-sync request with their own clocks, heartbeats come once a second",
          "[sim][world]") {
  SimWorldOptions options;
  options.camera = CameraOutput::Blank;
  options.horizon_s = 4;
  auto created = SimWorld::create(scenario("imu_clock_offset_s 0.5\nimu_clock_drift_ppm 100\nbus_jitter_us 0\n"), options);
  REQUIRE(created);
  auto& world = *created;
  REQUIRE(world->advance_to(1.0));
  fw::StampedCanFrame f;
  while (world->bus().receive(f, 0) == hw::CanReceive::Frame) {
  }
  auto request = fw::encode(fw::TimeSyncRequest{7, 1000000});
  REQUIRE(request);
  REQUIRE(world->bus().send(request->frame));
  REQUIRE(world->advance_to(1.0 + 0.002));
  int replies = 0, beats = 0;
  while (world->bus().receive(f, 0) == hw::CanReceive::Frame) {
    if (auto r = fw::decode_time_sync_reply(f.frame)) {
      ++replies;
      CHECK(r->sequence == 7);
      // Reached the nodes at 1.0005 s (command latency); the IMU's clock runs offset and fast.
      if (r->node == fw::kNodeImu) CHECK(r->device_stamp_us == std::llround((0.5 + 1.0001 * 1.0005) * 1e6));
      else CHECK(r->device_stamp_us == 1000500);
    }
  }
  CHECK(replies == 2);
  CHECK(world->stats().time_syncs_answered == 1);
  REQUIRE(world->advance_to(3.01));
  while (world->bus().receive(f, 0) == hw::CanReceive::Frame) {
    if (auto h = fw::decode_heartbeat(f.frame)) {
      ++beats;
      CHECK(h->state == fw::NodeState::Operational);
    }
  }
  CHECK(beats == 4);  // IMU at 2 s and 3 s, head at 1.5 s and 2.5 s
}

TEST_CASE("world: with the head left alone the camera renders exactly the frames `epichead sim` writes",
          "[sim][world][render]") {
  Scenario s = scenario("antialias 1\n");
  s.frames = 1;
  epichead::testing::TempDir dir("epichead_simworld");
  REQUIRE(write_sequence(s, dir.str()));
  const cv::Mat expected = cv::imread(dir / "frames/000000.png", cv::IMREAD_COLOR);
  REQUIRE(!expected.empty());
  SimWorldOptions options;  // full size, rendered
  auto world = SimWorld::create(s, options);
  REQUIRE(world);
  REQUIRE((*world)->camera().start());
  hw::CameraFrame frame;
  // Waiting on the camera moves the world's time to when frame 0 is ready.
  REQUIRE((*world)->camera().next_frame(frame, 1.0) == hw::CameraRead::Frame);
  CHECK((*world)->now_s() == Approx(s.first_frame_s + 0.5 * 0.008 + s.camera_latency_s).margin(1e-9));
  CHECK(frame.t_s == s.first_frame_s);
  REQUIRE(frame.width == expected.cols);
  REQUIRE(frame.height == expected.rows);
  REQUIRE(frame.format == hw::PixelFormat::Bgr24);
  const cv::Mat got(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.data),
                    static_cast<std::size_t>(frame.stride_bytes));
  CHECK(cv::norm(got, expected, cv::NORM_INF) == 0);
}
