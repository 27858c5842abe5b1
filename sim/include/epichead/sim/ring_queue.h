#pragma once
// A first-in first-out queue of fixed capacity that never allocates after construction: the
// simulated bus's queues (frames per IMU sample must not allocate). Hand-written because
// std::deque allocates blocks as it goes and no library on our Debian list has one.
#include <cstddef>
#include <vector>

namespace epichead::sim {

template <class T>
class RingQueue {
 public:
  explicit RingQueue(std::size_t capacity = 0) : items_(capacity) {}

  bool empty() const { return size_ == 0; }
  bool full() const { return size_ == items_.size(); }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return items_.size(); }
  // False (and nothing stored) when full.
  bool push(const T& item) {
    if (full()) return false;
    items_[(head_ + size_) % items_.size()] = item;
    ++size_;
    return true;
  }
  const T& front() const { return items_[head_]; }
  // The i-th item from the front (i < size()).
  const T& at(std::size_t i) const { return items_[(head_ + i) % items_.size()]; }
  const T& back() const { return items_[(head_ + size_ - 1) % items_.size()]; }
  void pop() {
    head_ = (head_ + 1) % items_.size();
    --size_;
  }

 private:
  std::vector<T> items_;
  std::size_t head_ = 0, size_ = 0;
};

}  // namespace epichead::sim
