#pragma once
// Files built into the program: the built-in scenarios (sim/scenarios/*.scn) and the scenes'
// assets (sim/scenes: CAO models, photos), so that a binary that is moved, installed or run from
// another checkout needs no source tree. Names are paths relative to sim/ in the source tree:
// "scenarios/mockup_walk.scn", "scenes/board.jpg".
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace epichead::sim {

// The bytes of a built-in file; nullopt for a name that is not built in.
std::optional<std::span<const std::byte>> builtin_asset(std::string_view name);
// The same bytes as text (scenarios, CAO models).
std::optional<std::string_view> builtin_asset_text(std::string_view name);
// Every built-in file's name, sorted.
const std::vector<std::string_view>& builtin_asset_names();

}  // namespace epichead::sim
