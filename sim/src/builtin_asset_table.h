#pragma once
// The table of files built into the program, generated at build time into the build tree's
// sim/builtin_asset_table.cpp by cmake/embed_files.cmake (sorted by name). Read it through
// epichead/sim/builtin_asset.h.
#include <cstddef>

namespace epichead::sim::detail {

struct BuiltinAssetEntry {
  const char* name;           // path relative to sim/, e.g. "scenarios/mockup_walk.scn"
  const unsigned char* data;  // `size` bytes followed by a 0 byte
  std::size_t size;
};

extern const BuiltinAssetEntry kBuiltinAssets[];
extern const std::size_t kBuiltinAssetCount;

}  // namespace epichead::sim::detail
