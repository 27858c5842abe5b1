#pragma once
// The detection templates on disk, so that a model's templates are rendered once: a small
// binary file named by a key of everything they depend on (model, camera, options).
//   "EPHDTPL1" | u64 key | u32 count | count x record
//   record: i32 view, i32 roll, i32 distance | f32 distance_m, f32 centre_dx, f32 centre_dy |
//           u8 levels | levels x (i32 width, i32 height, i32 pyramid_level, u32 n, n x (i16 x, i16 y, u8 label))
// Little-endian. Reading checks every count and value against what a template can hold, so a
// truncated, stale or garbled file is an error value (the detector then rebuilds), never a crash.
#include <cstdint>
#include <expected>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/rgbd/linemod.hpp>

namespace epichead::vision::detail {

// Where a template came from and where the object's centre projects relative to its top-left.
struct TemplateSpec {
  int view = 0, roll = 0, distance = 0;  // indices into the view, roll and distance grids
  float distance_m = 0;
  float centre_dx = 0, centre_dy = 0;    // object centre minus the template's top-left, level-0 px
};

struct TemplateRecord {
  TemplateSpec spec;
  std::vector<cv::linemod::Template> levels;  // one per pyramid level, as linemod made them
};

inline constexpr std::size_t kMaxCachedTemplates = 1u << 20;

std::string encode_template_cache(std::uint64_t key, const std::vector<TemplateRecord>& records);
// `name` is used in messages. A key other than `key` is an error ("made for another model,
// camera or options").
std::expected<std::vector<TemplateRecord>, std::string> decode_template_cache(std::string_view bytes, std::uint64_t key,
                                                                              const std::string& name);

std::expected<std::vector<TemplateRecord>, std::string> read_template_cache(const std::string& path, std::uint64_t key);
// Writes to a temporary file beside `path` and renames it, so a reader never sees half a file.
std::expected<void, std::string> write_template_cache(const std::string& path, std::uint64_t key,
                                                      const std::vector<TemplateRecord>& records);

}  // namespace epichead::vision::detail
