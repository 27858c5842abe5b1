// The control thread's hand-off queue (common/spsc_queue.h): FIFO, a full queue refuses without
// blocking, the high-water mark, and one producer and one consumer thread moving a long sequence
// through a small queue without losing, duplicating or reordering an item.
#include <catch2/catch.hpp>

#include <cstdint>
#include <thread>

#include "epichead/common/spsc_queue.h"

using epichead::common::SpscQueue;

TEST_CASE("spsc queue: first in, first out, full refuses, empty gives nothing", "[common][spsc]") {
  SpscQueue<int> q(3);
  CHECK(q.capacity() == 3);
  int out = -1;
  CHECK_FALSE(q.try_pop(out));
  CHECK(q.try_push(1));
  CHECK(q.try_push(2));
  CHECK(q.try_push(3));
  CHECK_FALSE(q.try_push(4));  // full: refused, nothing overwritten
  CHECK(q.size() == 3);
  CHECK(q.high_water() == 3);
  REQUIRE(q.try_pop(out));
  CHECK(out == 1);
  CHECK(q.try_push(5));  // the freed slot, across the wrap
  for (int expected : {2, 3, 5}) {
    REQUIRE(q.try_pop(out));
    CHECK(out == expected);
  }
  CHECK_FALSE(q.try_pop(out));
  CHECK(q.size() == 0);
  CHECK(q.high_water() == 3);
}

TEST_CASE("spsc queue: a producer and a consumer thread pass 200000 items in order", "[common][spsc]") {
  SpscQueue<std::uint64_t> q(16);
  constexpr std::uint64_t kItems = 200000;
  std::uint64_t refused = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems;) {
      if (q.try_push(i)) ++i;
      else ++refused;  // the producer never waits inside the queue: it decides (here: retry)
    }
  });
  std::uint64_t expected = 0, out_of_order = 0, item = 0;
  while (expected < kItems) {
    if (!q.try_pop(item)) continue;
    out_of_order += item != expected;
    expected = item + 1;
  }
  producer.join();
  CHECK(out_of_order == 0);
  CHECK(expected == kItems);
  CHECK_FALSE(q.try_pop(item));
  CHECK(q.high_water() <= 16);
}
