#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "epichead/sim/builtin_asset.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/scene_library.h"

namespace fs = std::filesystem;
using namespace epichead::sim;

namespace {

const fs::path kSimDir = fs::path(EPICHEAD_SOURCE_DIR) / "sim";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The source files that must be built in: every scenario, scene model and photo.
std::vector<std::string> source_asset_names() {
  std::vector<std::string> names;
  for (const char* folder : {"scenarios", "scenes"})
    for (const auto& e : fs::directory_iterator(kSimDir / folder)) {
      const std::string ext = e.path().extension().string();
      if (ext == ".scn" || ext == ".cao" || ext == ".jpg") names.push_back(std::string(folder) + "/" + e.path().filename().string());
    }
  std::sort(names.begin(), names.end());
  return names;
}

bool same_bytes(std::span<const std::byte> a, const std::string& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), b.size()) == 0;
}

}  // namespace

TEST_CASE("every scenario, scene model and photo in sim/ is built in, byte-identical to its file", "[sim][builtin_asset]") {
  const auto names = source_asset_names();
  REQUIRE(names.size() >= 16);  // 6 scenarios, 6 models, 4 photos
  CHECK(std::equal(names.begin(), names.end(), builtin_asset_names().begin(), builtin_asset_names().end()));
  for (const auto& name : names) {
    CAPTURE(name);
    const auto bytes = builtin_asset(name);
    REQUIRE(bytes);
    CHECK(same_bytes(*bytes, slurp(kSimDir / name)));
    const auto text = builtin_asset_text(name);
    REQUIRE(text);
    CHECK(text->size() == bytes->size());
    CHECK(static_cast<const void*>(text->data()) == static_cast<const void*>(bytes->data()));
  }
}

TEST_CASE("every built-in scenario and scene model is built in, the models as their CAO text", "[sim][builtin_asset]") {
  for (const auto& name : builtin_scenario_names()) {
    CAPTURE(name);
    CHECK(builtin_asset_text("scenarios/" + name + ".scn"));
    auto s = find_scenario(name);
    REQUIRE(s);
    CHECK(s->name == name);
  }
  for (const auto& name : scene_names()) {
    CAPTURE(name);
    const auto cao = scene_model_cao(name);
    REQUIRE(cao);
    CHECK(*cao == slurp(kSimDir / "scenes" / (name + ".cao")));
  }
}

TEST_CASE("a built-in photo decodes from memory to the same pixels as the file on disk", "[sim][builtin_asset]") {
  for (const char* name : {"board.jpg", "building.jpg", "stuff.jpg", "graf1.jpg"}) {
    CAPTURE(name);
    const auto bytes = builtin_asset(std::string("scenes/") + name);
    REQUIRE(bytes);
    const cv::Mat encoded(1, static_cast<int>(bytes->size()), CV_8UC1, const_cast<std::byte*>(bytes->data()));
    const cv::Mat decoded = cv::imdecode(encoded, cv::IMREAD_COLOR);
    const cv::Mat read = cv::imread((kSimDir / "scenes" / name).string(), cv::IMREAD_COLOR);
    REQUIRE(!decoded.empty());
    REQUIRE(decoded.size() == read.size());
    REQUIRE(decoded.type() == read.type());
    CHECK(cv::norm(decoded, read, cv::NORM_INF) == 0);
  }
}

TEST_CASE("an unknown asset name is not built in", "[sim][builtin_asset]") {
  CHECK(!builtin_asset("scenarios/no_such.scn"));
  CHECK(!builtin_asset_text("scenarios/no_such.scn"));
  CHECK(!builtin_asset(""));
  CHECK(!builtin_asset("mockup_walk.scn"));  // names are paths relative to sim/
  CHECK(!builtin_asset("scenarios/README.md"));
  CHECK(!scene_model_cao("no_such_scene"));
}
