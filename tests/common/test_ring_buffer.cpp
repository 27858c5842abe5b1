#include <catch2/catch.hpp>

#include <vector>

#include "epichead/common/ring_buffer.h"

using epichead::common::RingBuffer;

namespace {

// The items from oldest to newest.
template <class Ring>
std::vector<int> items(const Ring& r) {
  std::vector<int> out;
  for (std::size_t i = 0; i < r.size(); ++i) out.push_back(r[i]);
  return out;
}

}  // namespace

TEST_CASE("an empty ring holds nothing and keeps its capacity", "[common][ring]") {
  RingBuffer<int> r(3);
  CHECK(r.empty());
  CHECK_FALSE(r.full());
  CHECK(r.size() == 0);
  CHECK(r.capacity() == 3);
  r.push_overwrite(1);
  r.clear();
  CHECK(r.empty());
  CHECK(r.capacity() == 3);
  r.push_overwrite(7);
  CHECK(r.oldest() == 7);
  CHECK(r.newest() == 7);
}

TEST_CASE("push_overwrite drops the oldest when full and indexes from the oldest across the wrap", "[common][ring]") {
  RingBuffer<int> r(3);
  for (int v = 1; v <= 3; ++v) r.push_overwrite(v);
  CHECK(r.full());
  CHECK(items(r) == std::vector<int>{1, 2, 3});
  for (int v = 4; v <= 8; ++v) r.push_overwrite(v);  // wraps more than once
  CHECK(r.size() == 3);
  CHECK(items(r) == std::vector<int>{6, 7, 8});
  CHECK(r.oldest() == 6);
  CHECK(r.newest() == 8);
}

TEST_CASE("try_push refuses when full and keeps what the ring holds", "[common][ring]") {
  RingBuffer<int> r(2);
  CHECK(r.try_push(1));
  CHECK(r.try_push(2));
  CHECK_FALSE(r.try_push(3));
  CHECK(items(r) == std::vector<int>{1, 2});
  r.pop_front();
  CHECK(r.try_push(3));  // the freed slot is the wrapped one
  CHECK(items(r) == std::vector<int>{2, 3});
  r.pop_front();
  r.pop_front();
  CHECK(r.empty());
  CHECK(r.try_push(4));
  CHECK(r.oldest() == 4);
}

TEST_CASE("a ring of capacity 1 holds the newest item only", "[common][ring]") {
  RingBuffer<int> r(1);
  r.push_overwrite(1);
  r.push_overwrite(2);
  CHECK(r.size() == 1);
  CHECK(r.oldest() == 2);
  CHECK(r.newest() == 2);
  CHECK_FALSE(r.try_push(3));
  r.pop_front();
  CHECK(r.empty());
  CHECK(r.try_push(3));
  CHECK(r[0] == 3);
}

TEST_CASE("a ring of capacity 0 drops every push", "[common][ring]") {
  RingBuffer<int> r;
  r.push_overwrite(1);
  CHECK(r.empty());
  CHECK_FALSE(r.try_push(1));
}

TEST_CASE("push_slot gives the newest slot to fill in place, reusing the dropped oldest", "[common][ring]") {
  RingBuffer<int> r(2);
  r.push_slot() = 1;
  r.push_slot() = 2;
  int& slot = r.push_slot();
  CHECK(slot == 1);  // the dropped oldest's storage
  slot = 3;
  CHECK(items(r) == std::vector<int>{2, 3});
}

TEST_CASE("a ring with compile-time capacity behaves like one sized at construction", "[common][ring]") {
  RingBuffer<int, 3> r;
  CHECK(r.capacity() == 3);
  for (int v = 1; v <= 5; ++v) r.push_overwrite(v);
  CHECK(items(r) == std::vector<int>{3, 4, 5});
  r[0] = 9;
  CHECK(r.oldest() == 9);
  r.pop_front();
  CHECK(items(r) == std::vector<int>{4, 5});
}
