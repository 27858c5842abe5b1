#pragma once
// The element of a JSON array of objects whose `key` holds `value`, as the tools' reports list
// their ids and messages; a test that looks for one the report lacks fails naming it.
#include <string>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

namespace epichead::testing {

inline const nlohmann::json& entry_where(const nlohmann::json& array, const std::string& key, const std::string& value) {
  for (const auto& e : array)
    if (e.contains(key) && e[key] == value) return e;
  FAIL(key << " " << value << " not in the report");
  static const nlohmann::json none;
  return none;
}

}  // namespace epichead::testing
