// The `epichead run --config` reader: the controller's gains come from the file, a gain the
// controller does not have or out of its range is an error naming it, any other unknown key too,
// --help lists them, and docs/run_config.md documents exactly the keys the reader knows.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/run_tool.h"
#include "common/temp_dir.h"
#include "epichead/head/onboard_loop.h"
#include "run_config.h"

namespace {

using epichead::testing::TempDir;
using epichead::tools::read_run_config;

constexpr const char* kFiles = R"("model": "m.cao", "camera_calibration": "c.yaml", "init_pose": "i.csv")";

std::string write_config(const TempDir& dir, const std::string& extra) {
  return dir.write("robot.json", std::string("{ ") + kFiles + (extra.empty() ? "" : ", " + extra) + " }");
}

}  // namespace

TEST_CASE("run config: the controller's defaults stand when the file gives no gains") {
  TempDir dir;
  const auto c = read_run_config(write_config(dir, ""));
  REQUIRE(c);
  const epichead::head::HeadControllerOptions defaults;
  const auto o = epichead::tools::controller_options(*c, defaults);
  CHECK(o.stabilise_gain_per_s == defaults.stabilise_gain_per_s);
  CHECK(o.fixate_gain_per_s == defaults.fixate_gain_per_s);
  CHECK(o.backlash.pan_rad == 0);
}

TEST_CASE("run config: gains and backlash are read into the controller's options") {
  TempDir dir;
  const auto c = read_run_config(write_config(
      dir, R"("controller": { "stabilise_gain_per_s": 42, "fixate_gain_per_s": 2.5, "rate_lead_s": 0.006,
                               "hold_max_rate_radps": 1.25 },
             "head": { "pan_backlash_rad": 0.004 })"));
  REQUIRE(c);
  const auto o = epichead::tools::controller_options(*c, epichead::head::HeadControllerOptions{});
  CHECK(o.stabilise_gain_per_s == 42);
  CHECK(o.fixate_gain_per_s == 2.5);
  CHECK(o.rate_lead_s == 0.006);
  CHECK(o.hold_max_rate_radps == 1.25);
  CHECK(o.backlash.pan_rad == 0.004);
  CHECK(o.target_rate_filter_s == epichead::head::HeadControllerOptions{}.target_rate_filter_s);
}

TEST_CASE("run config: an unknown gain, a gain out of range or of the wrong type is an error naming it") {
  TempDir dir;
  const auto unknown = read_run_config(write_config(dir, R"("controller": { "stabilize_gain_per_s": 42 })"));
  REQUIRE_FALSE(unknown);
  CHECK(unknown.error().find("controller.stabilize_gain_per_s") != std::string::npos);
  const auto negative = read_run_config(write_config(dir, R"("controller": { "fixate_gain_per_s": -1 })"));
  REQUIRE_FALSE(negative);
  CHECK(negative.error().find("controller.fixate_gain_per_s") != std::string::npos);
  const auto text = read_run_config(write_config(dir, R"("controller": { "hold_gain_per_s": "10" })"));
  REQUIRE_FALSE(text);
  CHECK(text.error().find("controller.hold_gain_per_s") != std::string::npos);
  const auto not_object = read_run_config(write_config(dir, R"("controller": 3)"));
  REQUIRE_FALSE(not_object);
  CHECK(not_object.error().find("controller must be an object") != std::string::npos);
}

TEST_CASE("run config: the CAN interface and its receive queue, checked") {
  TempDir dir;
  const auto c = read_run_config(write_config(
      dir, R"("can": { "interface": "vcan1", "receive_buffer_bytes": 4194304, "time_sync_max_round_trip_ms": 45 })"));
  REQUIRE(c);
  CHECK(c->time_sync_max_round_trip_s == Approx(0.045));
  CHECK(c->can.interface == "vcan1");
  CHECK(c->can.receive_buffer_bytes == 4194304);
  const auto defaults = read_run_config(write_config(dir, R"("can": { "interface": "can2" })"));
  REQUIRE(defaults);
  CHECK(defaults->can.receive_buffer_bytes == epichead::hw::SocketCanOptions{}.receive_buffer_bytes);
  const auto negative = read_run_config(write_config(dir, R"("can": { "receive_buffer_bytes": -5 })"));
  REQUIRE_FALSE(negative);
  CHECK(negative.error().find("can.receive_buffer_bytes") != std::string::npos);
  const auto unsafe = read_run_config(write_config(dir, R"("can": { "time_sync_max_round_trip_ms": 70 })"));
  REQUIRE_FALSE(unsafe);
  CHECK(unsafe.error().find("can.time_sync_max_round_trip_ms") != std::string::npos);
  const auto not_object = read_run_config(write_config(dir, R"("can": "vcan0")"));
  REQUIRE_FALSE(not_object);
  CHECK(not_object.error().find("can must be an object") != std::string::npos);
}

TEST_CASE("run --help lists the configuration keys and the controller's gains") {
  TempDir scratch;
  const auto r = epichead::testing::run_epichead(scratch, "run --help");
  CHECK(r.exit_code == 0);
  for (const char* key : {"camera_calibration", "init_pose", "pan_backlash_rad", "stabilise_gain_per_s", "fixate_gain_per_s",
                          "rate_lead_s", "hold_max_rate_radps", "receive_buffer_bytes", "time_sync_max_round_trip_ms"})
    CHECK(r.out.find(key) != std::string::npos);
  // The defaults shown are the controller's own.
  CHECK(r.out.find("\"stabilise_gain_per_s\": 60") != std::string::npos);
}

TEST_CASE("run config: without init_pose the object is detected, reacquire is a bool, template_cache a path") {
  TempDir dir;
  const auto plain = read_run_config(dir.write("a.json", R"({ "model": "m.cao", "camera_calibration": "c.yaml" })"));
  REQUIRE(plain);
  CHECK(plain->init_pose.empty());
  CHECK(plain->reacquire);
  CHECK(plain->template_cache.empty());
  const auto set = read_run_config(dir.write(
      "b.json", R"({ "model": "m.cao", "camera_calibration": "c.yaml", "reacquire": false, "template_cache": "cache" })"));
  REQUIRE(set);
  CHECK_FALSE(set->reacquire);
  CHECK(set->template_cache == (std::filesystem::path(dir.path) / "cache").string());
  const auto bad = read_run_config(dir.write("c.json", R"({ "model": "m.cao", "camera_calibration": "c.yaml", "reacquire": 1 })"));
  REQUIRE_FALSE(bad);
  CHECK(bad.error().find("'reacquire' must be true or false") != std::string::npos);
  const auto bad_path = read_run_config(dir.write("d.json", R"({ "model": "m.cao", "camera_calibration": "c.yaml", "init_pose": 3 })"));
  REQUIRE_FALSE(bad_path);
  CHECK(bad_path.error().find("'init_pose' must be a string") != std::string::npos);
}

TEST_CASE("run config: object_up is a non-zero direction, read as a unit vector, and none by default") {
  TempDir dir;
  CHECK_FALSE(read_run_config(write_config(dir, ""))->object_up);
  const auto up = read_run_config(write_config(dir, R"("object_up": [0, 0, 2])"));
  REQUIRE(up);
  REQUIRE(up->object_up);
  CHECK(up->object_up->isApprox(Eigen::Vector3d::UnitZ()));
  for (const char* bad : {R"("object_up": [0, 0, 0])", R"("object_up": [0, 1])", R"("object_up": "up")",
                          R"("object_up": [0, "1", 0])", R"("object_up": [0, 1, 0, 0])"}) {
    INFO(bad);
    const std::string path = write_config(dir, bad);
    const auto c = read_run_config(path);
    REQUIRE_FALSE(c);
    CHECK(c.error().starts_with(path + ": 'object_up' must be [x, y, z]"));
  }
}

namespace {

// The rows of docs/run_config.md's key table: key, type, unit, default, meaning (backticks taken
// off the key and the default).
std::vector<std::vector<std::string>> documented_keys() {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& line : epichead::testing::lines_of(epichead::testing::slurp(EPICHEAD_SOURCE_DIR "/docs/run_config.md"))) {
    if (!line.starts_with("| `")) continue;
    std::vector<std::string> cells;
    std::size_t start = 1;
    for (std::size_t bar; (bar = line.find(" | ", start)) != std::string::npos; start = bar + 3)
      cells.push_back(line.substr(start, bar - start));
    cells.push_back(line.substr(start, line.size() - start - 2));  // the last, before " |"
    for (std::string& cell : cells) {
      while (!cell.empty() && cell.front() == ' ') cell.erase(0, 1);
      if (cell.size() >= 2 && cell.front() == '`' && cell.back() == '`') cell = cell.substr(1, cell.size() - 2);
    }
    rows.push_back(cells);
  }
  return rows;
}

}  // namespace

TEST_CASE("docs/run_config.md lists exactly the keys the reader knows, with their types and defaults") {
  const auto rows = documented_keys();
  const auto keys = epichead::tools::run_config_keys(epichead::head::OnboardOptions{}.controller);
  REQUIRE(rows.size() == keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    INFO("row " << i + 1 << ": " << keys[i].name);
    REQUIRE(rows[i].size() == 5);
    CHECK(rows[i][0] == keys[i].name);
    CHECK(rows[i][1] == keys[i].type);
    CHECK(rows[i][3] == keys[i].default_json);
    CHECK_FALSE(rows[i][2].empty());  // a unit, or '–'
    CHECK(rows[i][4].size() > 10);    // a meaning
  }
  // `run --help` shows the same defaults for the controller as the loop uses.
  CHECK(epichead::head::OnboardOptions{}.controller.stabilise_gain_per_s ==
        epichead::head::HeadControllerOptions{}.stabilise_gain_per_s);
}

TEST_CASE("run config: a file giving every documented key is read") {
  TempDir dir;
  nlohmann::json j = nlohmann::json::object();
  for (const auto& key : epichead::tools::run_config_keys(epichead::head::HeadControllerOptions{})) {
    nlohmann::json value;
    if (key.type == "array") value = {0, 0, 1};
    else if (key.default_json == "required" || key.default_json == "none") value = "some/file";
    else value = nlohmann::json::parse(key.default_json);
    const std::size_t dot = key.name.find('.');
    if (dot == std::string::npos) j[key.name] = value;
    else j[key.name.substr(0, dot)][key.name.substr(dot + 1)] = value;
  }
  const auto c = read_run_config(dir.write("all.json", j.dump()));
  INFO((c ? std::string() : c.error()));
  CHECK(c);
}

TEST_CASE("run config: an unknown key, at the top or in a section, is an error naming the file and the key") {
  TempDir dir;
  const std::string path = write_config(dir, R"("camera": { "device": "/dev/video2", "widht": 1280 })");
  const auto typo = read_run_config(path);
  REQUIRE_FALSE(typo);
  CHECK(typo.error().starts_with(path + ": "));
  CHECK(typo.error().find("unknown key \"camera.widht\"") != std::string::npos);
  const auto top = read_run_config(write_config(dir, R"("reaquire": false)"));
  REQUIRE_FALSE(top);
  CHECK(top.error().find("unknown key \"reaquire\"") != std::string::npos);
  const auto can = read_run_config(write_config(dir, R"("can": { "interface": "can1", "bitrate": 1000000 })"));
  REQUIRE_FALSE(can);
  CHECK(can.error().find("unknown key \"can.bitrate\"") != std::string::npos);
  const auto head = read_run_config(write_config(dir, R"("head": { "backlash_rad": 0.01 })"));
  REQUIRE_FALSE(head);
  CHECK(head.error().find("unknown key \"head.backlash_rad\"") != std::string::npos);
  // A key with a line break in it stays on one line.
  const auto newline = read_run_config(write_config(dir, R"("mo\nde": "hold")"));
  REQUIRE_FALSE(newline);
  CHECK(newline.error().find('\n') == std::string::npos);
}
