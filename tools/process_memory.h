#pragma once
// This process's resident memory, for long runs that must not grow (sim-run --soak).
#include <optional>

namespace epichead::tools {

// Resident set size in KiB (/proc/self/statm), or nothing where /proc is not readable.
std::optional<double> resident_kib();

}  // namespace epichead::tools
