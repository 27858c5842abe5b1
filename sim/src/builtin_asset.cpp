#include "epichead/sim/builtin_asset.h"

#include <algorithm>

#include "builtin_asset_table.h"

namespace epichead::sim {
namespace {

std::span<const detail::BuiltinAssetEntry> table() { return {detail::kBuiltinAssets, detail::kBuiltinAssetCount}; }

const detail::BuiltinAssetEntry* find(std::string_view name) {
  const auto all = table();
  auto before = [](const detail::BuiltinAssetEntry& e, std::string_view n) { return std::string_view(e.name) < n; };
  const auto it = std::lower_bound(all.begin(), all.end(), name, before);
  return it != all.end() && it->name == name ? &*it : nullptr;
}

}  // namespace

std::optional<std::span<const std::byte>> builtin_asset(std::string_view name) {
  const auto* e = find(name);
  if (!e) return std::nullopt;
  return std::as_bytes(std::span<const unsigned char>(e->data, e->size));
}

std::optional<std::string_view> builtin_asset_text(std::string_view name) {
  const auto* e = find(name);
  if (!e) return std::nullopt;
  return std::string_view(reinterpret_cast<const char*>(e->data), e->size);
}

const std::vector<std::string_view>& builtin_asset_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> n;
    for (const auto& e : table()) n.emplace_back(e.name);
    return n;
  }();
  return names;
}

}  // namespace epichead::sim
