// `epichead bench [--json] [FILTER]`: runs the registered benchmarks and prints, for each, the
// median and p99 time per iteration and the heap allocations per iteration.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <regex>

#include "bench/bench.h"
#include "command.h"
#include "epichead/common/allocation_counter.h"

namespace epichead::tools {
namespace {

struct BenchResult {
  std::string name;
  double median_us = 0, p99_us = 0, allocs_per_iter = 0;
  long long iterations = 0;
  int items = 0;  // per iteration (Benchmark::items)
  double ns_per_item() const { return items > 0 ? median_us * 1000.0 / items : 0.0; }
};

using Clock = std::chrono::steady_clock;

// Times batches of iterations: a batch lasts at least ~20 us so that clock overhead is small,
// and the statistics are over batches (time per iteration = batch time / batch size).
BenchResult run_one(const bench::Benchmark& b, double budget_s) {
  bench::Iteration body = b.make();
  // Warm-up: lets buffers reach their working size and caches fill.
  const auto warm_end = Clock::now() + std::chrono::milliseconds(50);
  long long warm = 0;
  while (Clock::now() < warm_end || warm < 3) { body(); ++warm; }
  // Batch size from the warm-up rate.
  const double per_iter_s = 0.05 / static_cast<double>(warm);
  const long long batch = std::max(1LL, static_cast<long long>(20e-6 / std::max(per_iter_s, 1e-9)));
  std::vector<double> samples_us;
  samples_us.reserve(4096);
  long long iterations = 0;
  const unsigned long long allocs_before = common::allocation_count();
  const auto end = Clock::now() + std::chrono::duration<double>(budget_s);
  while ((Clock::now() < end && samples_us.size() < samples_us.capacity()) || samples_us.size() < 10) {
    const auto t0 = Clock::now();
    for (long long i = 0; i < batch; ++i) body();
    const auto t1 = Clock::now();
    samples_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count() / static_cast<double>(batch));
    iterations += batch;
  }
  const unsigned long long allocs = common::allocation_count() - allocs_before;
  std::sort(samples_us.begin(), samples_us.end());
  auto quantile = [&](double q) {
    const std::size_t i = std::min(samples_us.size() - 1, static_cast<std::size_t>(q * static_cast<double>(samples_us.size())));
    return samples_us[i];
  };
  return {b.name, quantile(0.5), quantile(0.99), static_cast<double>(allocs) / static_cast<double>(iterations), iterations,
          b.items};
}

const CommandRegistration registration{
    "bench", "Run the benchmarks: median and p99 time per iteration, heap allocations per iteration",
    [](CLI::App& app) {
      auto json = std::make_shared<bool>(false);
      auto filter = std::make_shared<std::string>();
      auto budget_s = std::make_shared<double>(1.0);
      auto list = std::make_shared<bool>(false);
      app.add_flag("--json", *json,
                   "One JSON object per line: name, median_us, p99_us, allocs_per_iter, iterations, and "
                   "ns_per_item for benchmarks with work items (a window's pixels)");
      app.add_option("--time", *budget_s, "Measuring time per benchmark in seconds")->check(CLI::Range(0.01, 60.0));
      app.add_flag("--list", *list, "List the benchmark names and exit");
      app.add_option("filter", *filter, "Run only benchmarks whose name matches this regular expression");
      return [=]() -> int {
        std::regex re;
        try {
          re = std::regex(filter->empty() ? std::string(".*") : *filter);
        } catch (const std::regex_error& e) {
          return fail("bench", "bad FILTER regular expression '" + *filter + "': " + e.what());
        }
        auto benchmarks = bench::registry();
        std::sort(benchmarks.begin(), benchmarks.end(), [](auto& a, auto& b) { return a.name < b.name; });
        int ran = 0;
        if (!*json && !*list)
          std::printf("%-24s %12s %12s %14s %12s\n", "name", "median_us", "p99_us", "allocs/iter", "ns/item");
        for (const auto& b : benchmarks) {
          if (!std::regex_search(b.name, re)) continue;
          ++ran;
          if (*list) { std::printf("%s\n", b.name.c_str()); continue; }
          const BenchResult r = run_one(b, *budget_s);
          if (*json) {
            nlohmann::json j{{"name", r.name}, {"median_us", r.median_us}, {"p99_us", r.p99_us},
                             {"allocs_per_iter", r.allocs_per_iter}, {"iterations", r.iterations}};
            if (r.items > 0) j["ns_per_item"] = r.ns_per_item();
            std::cout << j.dump() << std::endl;
          } else {
            std::printf("%-24s %12.3f %12.3f %14.3f", r.name.c_str(), r.median_us, r.p99_us, r.allocs_per_iter);
            if (r.items > 0) std::printf(" %12.3f\n", r.ns_per_item());
            else std::printf(" %12s\n", "-");
            std::fflush(stdout);
          }
        }
        if (ran == 0) return fail("bench", "no benchmark matches '" + *filter + "'");
        return 0;
      };
    }};

}  // namespace
}  // namespace epichead::tools
