// A scenario's light level between keys, and finding a scenario: built in or a file (the
// parser: scenario_parser.cpp).
#include "epichead/sim/scenario.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "epichead/sim/builtin_asset.h"

namespace epichead::sim {

double Scenario::light_gain(double t_s) const {
  if (light.empty()) return 1.0;
  if (t_s <= light.front().t_s) return light.front().gain;
  if (t_s >= light.back().t_s) return light.back().gain;
  std::size_t i = 1;
  while (light[i].t_s < t_s) ++i;
  const LightKey& a = light[i - 1];
  const LightKey& b = light[i];
  const double u = (t_s - a.t_s) / (b.t_s - a.t_s);
  const double w = 0.5 - 0.5 * std::cos(std::numbers::pi * u);
  return a.gain + (b.gain - a.gain) * w;
}

std::expected<Scenario, std::string> load_scenario(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in || std::filesystem::is_directory(path)) return std::unexpected(path + ":0: cannot read the scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scenario(text.str(), path);
}

const std::vector<std::string>& builtin_scenario_names() {
  static const std::vector<std::string> names{"mockup_walk", "lampshade", "box_clutter", "office_pan", "can",
                                              "bowl", "late_entry", "box_cover", "stumble"};
  return names;
}

std::expected<Scenario, std::string> find_scenario(const std::string& name_or_path) {
  for (const auto& n : builtin_scenario_names()) {
    if (n != name_or_path) continue;
    // Built into the program (builtin_asset.h): no file to find, wherever the binary runs.
    const std::string file = n + ".scn";
    const auto text = builtin_asset_text("scenarios/" + file);
    if (!text) return std::unexpected(file + ":0: the built-in scenario is missing from the program");
    return parse_scenario(std::string(*text), file);
  }
  if (!std::filesystem::exists(name_or_path)) {
    std::string known;
    for (const auto& n : builtin_scenario_names()) known += (known.empty() ? "" : ", ") + n;
    return std::unexpected("no scenario '" + name_or_path + "' (neither a file nor a built-in: " + known + ")");
  }
  return load_scenario(name_or_path);
}

}  // namespace epichead::sim
