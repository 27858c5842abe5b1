#pragma once
// A bounded lock-free queue between exactly one producer thread and one consumer thread: the
// onboard loop's hand-offs between its control thread and the threads that must never hold it up
// (the vision worker, the recorder). Storage is sized once; push and pop allocate nothing, take
// no lock and make no system call, so a real-time thread may call them. A full queue refuses the
// item (the producer counts the drop): the producer never waits for the consumer.
//
// Ordering: the producer writes the slot, then publishes it with a release store of the tail;
// the consumer's acquire load of the tail makes the slot's contents visible (and the same the
// other way round for the head), as in the classic Lamport queue.
#include <atomic>
#include <cstddef>
#include <new>
#include <vector>

namespace epichead::common {

template <class T>
class SpscQueue {
 public:
  // Holds up to `capacity` items (at least 1).
  explicit SpscQueue(std::size_t capacity) : slots_(capacity < 1 ? 2 : capacity + 1) {}
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  std::size_t capacity() const { return slots_.size() - 1; }

  // Producer: appends a copy of `item`; false when full (nothing stored).
  bool try_push(const T& item) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t next = advance(tail);
    if (next == head_.load(std::memory_order_acquire)) return false;
    slots_[tail] = item;
    tail_.store(next, std::memory_order_release);
    note_size(next);
    return true;
  }

  // Consumer: moves the oldest item into `out`; false when empty.
  bool try_pop(T& out) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return false;
    out = slots_[head];
    head_.store(advance(head), std::memory_order_release);
    return true;
  }

  // Either thread: how many items are queued now (a snapshot: the other side may be moving).
  std::size_t size() const {
    const std::size_t head = head_.load(std::memory_order_acquire), tail = tail_.load(std::memory_order_acquire);
    return tail >= head ? tail - head : tail + slots_.size() - head;
  }
  // The most items ever queued at once, seen by the producer after a push.
  std::size_t high_water() const { return high_water_.load(std::memory_order_relaxed); }

 private:
  std::size_t advance(std::size_t i) const { return i + 1 == slots_.size() ? 0 : i + 1; }
  void note_size(std::size_t tail) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t n = tail >= head ? tail - head : tail + slots_.size() - head;
    if (n > high_water_.load(std::memory_order_relaxed)) high_water_.store(n, std::memory_order_relaxed);
  }

  std::vector<T> slots_;  // one slot stays empty: head == tail means empty, tail + 1 == head full
  // Producer and consumer indices on their own cache lines, so that the two threads do not
  // invalidate each other's line on every operation.
  alignas(64) std::atomic<std::size_t> head_{0};  // next slot to pop (consumer writes)
  alignas(64) std::atomic<std::size_t> tail_{0};  // next slot to fill (producer writes)
  alignas(64) std::atomic<std::size_t> high_water_{0};
};

}  // namespace epichead::common
