// `epichead bench`: the benchmark tool users and CI read figures from. Checks what it reports
// (not how fast anything is: speed is judged from benchmark runs, never by a timed test).
#include <catch2/catch.hpp>

#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/run_tool.h"

namespace {

using epichead::testing::ToolRun;

struct TempDir : epichead::testing::TempDir {
  TempDir() : epichead::testing::TempDir("epichead_test_bench_tool") {}
};

ToolRun bench(const TempDir& tmp, const std::string& args) { return epichead::testing::run_epichead(tmp, "bench " + args); }

std::vector<nlohmann::json> json_lines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

}  // namespace

TEST_CASE("bench reports the EPIC window per pixel and with no heap allocation per window", "[bench]") {
  TempDir tmp;
  const ToolRun r = bench(tmp, "--time 0.05 --json '^epic_window$'");
  REQUIRE(r.exit_code == 0);
  const auto lines = json_lines(r.out);
  REQUIRE(lines.size() == 1);
  const auto& j = lines[0];
  CHECK(j.at("name") == "epic_window");
  const double median_us = j.at("median_us").get<double>();
  CHECK(median_us > 0);
  // A 40 x 40 window: ns per pixel is the window's time over its 1600 pixels.
  REQUIRE(j.contains("ns_per_item"));
  CHECK(j.at("ns_per_item").get<double>() == Approx(median_us * 1000.0 / 1600.0));
  CHECK(j.at("allocs_per_iter").get<double>() == 0.0);
  CHECK(j.at("iterations").get<long long>() > 0);
}

TEST_CASE("bench's table has the per-item column, '-' where a benchmark has no items", "[bench]") {
  TempDir tmp;
  const ToolRun r = bench(tmp, "--time 0.02 '^epic_window$|^imu_step$'");
  REQUIRE(r.exit_code == 0);
  std::istringstream in(r.out);
  std::string header;
  std::getline(in, header);
  CHECK(header.find("ns/item") != std::string::npos);
  int rows = 0;
  for (std::string line; std::getline(in, line); ++rows) {
    std::istringstream cols(line);
    std::string name, median, p99, allocs, per_item;
    cols >> name >> median >> p99 >> allocs >> per_item;
    INFO(line);
    if (name == "imu_step") CHECK(per_item == "-");
    else CHECK(std::stod(per_item) > 0);
  }
  CHECK(rows == 2);
}

TEST_CASE("bench refuses a bad filter and a filter that matches nothing", "[bench]") {
  TempDir tmp;
  const ToolRun bad = bench(tmp, "'('");
  CHECK(bad.exit_code != 0);
  CHECK(bad.err.find("regular expression") != std::string::npos);
  const ToolRun none = bench(tmp, "'^no_such_benchmark$'");
  CHECK(none.exit_code != 0);
  CHECK(none.err.find("no benchmark matches") != std::string::npos);
}

TEST_CASE("bench --list names every benchmark, the detection ones among them", "[bench]") {
  TempDir tmp;
  const ToolRun r = bench(tmp, "--list");
  REQUIRE(r.exit_code == 0);
  for (const char* name : {"epic_window", "track_cycle", "imu_step", "detect_640x480", "detect_near", "detect_build_teabox",
                           "detect_build_300"}) {
    INFO(name);
    CHECK(("\n" + r.out).find(std::string("\n") + name + "\n") != std::string::npos);
  }
}
