// The detection template cache (vision/src/template_cache.h). Properties: no crash and no
// unbounded allocation on any bytes; errors are one line naming the file; what decodes encodes
// back to the same bytes (the format has one way to write each value set).
#include <cstring>
#include <string>

#include "fuzz_support.h"
#include "template_cache.h"

using namespace epichead::vision::detail;
using epichead::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  // The key the file claims, so that the fuzzer gets past the key check.
  std::uint64_t key = 0;
  if (size >= 16) std::memcpy(&key, data + 8, sizeof key);
  const auto records = decode_template_cache(bytes, key, "cache.bin");
  if (!records) {
    epichead::fuzz::check_one_line(records.error(), "template cache error");
    check(records.error().starts_with("cache.bin: "), "the error does not name the file: " + records.error());
    return 0;
  }
  check(!records->empty() && records->size() <= kMaxCachedTemplates, "a cache with no or too many templates was accepted");
  check(encode_template_cache(key, *records) == bytes, "decode -> encode changed the bytes");
  return 0;
}
