#include <catch2/catch.hpp>

#include <memory>
#include <vector>

#include "epichead/common/allocation_counter.h"
#include "epichead/common/ring_buffer.h"

using epichead::common::allocation_count;

TEST_CASE("the allocation counter counts every operator new", "[common][alloc]") {
  const auto before = allocation_count();
  auto a = std::make_unique<int>(1);
  auto b = std::make_unique<int[]>(4);
  std::vector<double> v(10);
  const auto after = allocation_count();  // before any assertion: Catch itself allocates
  CHECK(after - before == 3);
}

TEST_CASE("a ring allocates at construction only", "[common][ring][alloc]") {
  epichead::common::RingBuffer<std::vector<int>> r(4);
  std::vector<int> item{1, 2, 3};
  for (int i = 0; i < 4; ++i) r.push_overwrite(item);  // each slot gets its storage once
  const auto before = allocation_count();
  for (int i = 0; i < 100; ++i) {
    r.push_overwrite(item);
    r.pop_front();
    (void)r.try_push(item);
    r.push_slot()[0] = i;
  }
  const auto after = allocation_count();
  CHECK(after - before == 0);
}
