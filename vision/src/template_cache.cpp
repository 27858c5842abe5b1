#include "template_cache.h"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include <unistd.h>

namespace epichead::vision::detail {

namespace {

constexpr char kMagic[8] = {'E', 'P', 'H', 'D', 'T', 'P', 'L', '1'};
constexpr int kMaxLevels = 8;
constexpr int kMaxSidePx = 1 << 15;
constexpr std::uint32_t kMaxFeatures = 4096;

template <class T>
void put(std::string& out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

// Reads values from the bytes, remembering the first failure.
struct Reader {
  std::string_view in;
  std::size_t at = 0;
  bool ok = true;
  template <class T>
  T get() {
    T v{};
    if (!ok || in.size() - at < sizeof(T)) {
      ok = false;
      return v;
    }
    std::memcpy(&v, in.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
};

}  // namespace

std::string encode_template_cache(std::uint64_t key, const std::vector<TemplateRecord>& records) {
  std::string out(kMagic, sizeof kMagic);
  put<std::uint64_t>(out, key);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(records.size()));
  for (const auto& r : records) {
    put<std::int32_t>(out, r.spec.view);
    put<std::int32_t>(out, r.spec.roll);
    put<std::int32_t>(out, r.spec.distance);
    put<float>(out, r.spec.distance_m);
    put<float>(out, r.spec.centre_dx);
    put<float>(out, r.spec.centre_dy);
    put<std::uint8_t>(out, static_cast<std::uint8_t>(r.levels.size()));
    for (const auto& t : r.levels) {
      put<std::int32_t>(out, t.width);
      put<std::int32_t>(out, t.height);
      put<std::int32_t>(out, t.pyramid_level);
      put<std::uint32_t>(out, static_cast<std::uint32_t>(t.features.size()));
      for (const auto& f : t.features) {
        put<std::int16_t>(out, static_cast<std::int16_t>(f.x));
        put<std::int16_t>(out, static_cast<std::int16_t>(f.y));
        put<std::uint8_t>(out, static_cast<std::uint8_t>(f.label));
      }
    }
  }
  return out;
}

std::expected<std::vector<TemplateRecord>, std::string> decode_template_cache(std::string_view bytes, std::uint64_t key,
                                                                              const std::string& name) {
  auto error = [&](const std::string& what) { return std::unexpected(name + ": " + what); };
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    return error("not a template cache (no EPHDTPL1 header)");
  Reader r{bytes, sizeof kMagic};
  if (r.get<std::uint64_t>() != key) return error("made for another model, camera or options");
  const std::uint32_t count = r.get<std::uint32_t>();
  if (!r.ok) return error("truncated header");
  if (count == 0 || count > kMaxCachedTemplates) return error("template count " + std::to_string(count) + " out of range");
  std::vector<TemplateRecord> records;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::string where = "template " + std::to_string(i) + ": ";
    TemplateRecord rec;
    rec.spec.view = r.get<std::int32_t>();
    rec.spec.roll = r.get<std::int32_t>();
    rec.spec.distance = r.get<std::int32_t>();
    rec.spec.distance_m = r.get<float>();
    rec.spec.centre_dx = r.get<float>();
    rec.spec.centre_dy = r.get<float>();
    const int levels = r.get<std::uint8_t>();
    if (!r.ok) return error(where + "truncated");
    if (rec.spec.view < 0 || rec.spec.roll < 0 || rec.spec.distance < 0 || !(rec.spec.distance_m > 0) ||
        !std::isfinite(rec.spec.distance_m) || !std::isfinite(rec.spec.centre_dx) || !std::isfinite(rec.spec.centre_dy) ||
        std::abs(rec.spec.centre_dx) > kMaxSidePx || std::abs(rec.spec.centre_dy) > kMaxSidePx)
      return error(where + "view, distance or centre out of range");
    if (levels < 1 || levels > kMaxLevels) return error(where + "pyramid level count " + std::to_string(levels) + " out of range");
    for (int l = 0; l < levels; ++l) {
      cv::linemod::Template t;
      t.width = r.get<std::int32_t>();
      t.height = r.get<std::int32_t>();
      t.pyramid_level = r.get<std::int32_t>();
      const std::uint32_t n = r.get<std::uint32_t>();
      if (!r.ok) return error(where + "truncated");
      if (t.width < 0 || t.height < 0 || t.width > kMaxSidePx || t.height > kMaxSidePx || t.pyramid_level != l ||
          n == 0 || n > kMaxFeatures)
        return error(where + "size, level or feature count out of range");
      t.features.reserve(n);
      for (std::uint32_t k = 0; k < n; ++k) {
        const int x = r.get<std::int16_t>(), y = r.get<std::int16_t>(), label = r.get<std::uint8_t>();
        if (!r.ok) return error(where + "truncated");
        // linemod quantises orientation into 8 labels; a feature lies inside its template.
        if (x < 0 || y < 0 || x > t.width || y > t.height || label > 7) return error(where + "feature out of range");
        t.features.emplace_back(x, y, label);
      }
      rec.levels.push_back(std::move(t));
    }
    records.push_back(std::move(rec));
  }
  if (r.at != bytes.size()) return error("trailing bytes after the last template");
  return records;
}

std::expected<std::vector<TemplateRecord>, std::string> read_template_cache(const std::string& path, std::uint64_t key) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::unexpected(path + ": cannot read");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return decode_template_cache(bytes, key, path);
}

std::expected<void, std::string> write_template_cache(const std::string& path, std::uint64_t key,
                                                      const std::vector<TemplateRecord>& records) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  if (ec) return std::unexpected("cannot create " + fs::path(path).parent_path().string() + ": " + ec.message());
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    const std::string bytes = encode_template_cache(key, records);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) return std::unexpected(tmp + ": cannot write");
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    return std::unexpected("cannot write " + path);
  }
  return {};
}

}  // namespace epichead::vision::detail
