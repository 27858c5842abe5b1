#pragma once
// A ring of fixed capacity for the newest samples of a stream (IMU states, gyro attitudes,
// commands sent, bus frames in flight), like PX4 EKF2's RingBuffer<T>: storage is sized once,
// at construction (RingBuffer<T>) or at compile time (RingBuffer<T, N>), and nothing allocates
// after that. Items are indexed from the oldest (0) to the newest (size() - 1). Each user says
// which push it uses: push_overwrite() drops the oldest when full (a history of the latest
// samples), try_push() refuses (a queue that must not lose what it holds).
// Hand-written because std::deque allocates as it grows and no library on our Debian list has
// a fixed-capacity ring.
#include <array>
#include <cassert>
#include <cstddef>
#include <type_traits>
#include <vector>

namespace epichead::common {

inline constexpr std::size_t dynamic_capacity = 0;

template <class T, std::size_t N = dynamic_capacity>
class RingBuffer {
 public:
  // Capacity N (compile time) or `capacity` (once, here); 0 holds nothing and every push drops.
  RingBuffer()
    requires(N != dynamic_capacity)
  = default;
  explicit RingBuffer(std::size_t capacity = 0)
    requires(N == dynamic_capacity)
      : items_(capacity) {}

  std::size_t capacity() const { return items_.size(); }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == items_.size(); }

  // Appends `item` as the newest; when full, the oldest is dropped to make room.
  void push_overwrite(const T& item) {
    if (items_.empty()) return;
    push_slot() = item;
  }
  // Makes room for a newest item as push_overwrite() does and returns its slot for the caller to
  // fill in place (it holds whatever was there: a dropped oldest item or an earlier value).
  // Precondition: capacity() > 0.
  T& push_slot() {
    assert(!items_.empty());
    T& slot = items_[physical(size_)];
    if (full()) {
      head_ = physical(1);
    } else {
      ++size_;
    }
    return slot;
  }
  // Appends `item` as the newest; false (and nothing stored) when full.
  bool try_push(const T& item) {
    if (full()) return false;
    items_[physical(size_)] = item;
    ++size_;
    return true;
  }

  // Precondition for the accessors below: !empty() (operator[]: i < size()).
  T& oldest() { return items_[head_]; }
  const T& oldest() const { return items_[head_]; }
  T& newest() { return items_[physical(size_ - 1)]; }
  const T& newest() const { return items_[physical(size_ - 1)]; }
  // The i-th item from the oldest.
  T& operator[](std::size_t i) { return items_[physical(i)]; }
  const T& operator[](std::size_t i) const { return items_[physical(i)]; }

  // Drops the oldest item.
  void pop_front() {
    assert(size_ > 0);
    head_ = physical(1);
    --size_;
  }
  // Drops every item; the capacity stays.
  void clear() { head_ = size_ = 0; }

 private:
  // Storage index of the i-th item from the oldest (i <= capacity()).
  std::size_t physical(std::size_t i) const {
    const std::size_t k = head_ + i;
    return k >= items_.size() ? k - items_.size() : k;
  }

  std::conditional_t<N == dynamic_capacity, std::vector<T>, std::array<T, N>> items_{};
  std::size_t head_ = 0;  // storage index of the oldest item
  std::size_t size_ = 0;
};

}  // namespace epichead::common
