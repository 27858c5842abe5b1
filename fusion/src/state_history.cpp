#include "epichead/fusion/state_history.h"

namespace epichead::fusion {

StateEntry& StateHistory::push(const ImuSample& sample, bool with_state) {
  if (ring_.full()) evicted_t_s_ = ring_.oldest().sample.t_s;
  if (!with_state && first_state_seq_ <= end_seq_) first_state_seq_ = end_seq_ + 1;
  StateEntry& e = ring_.push_slot();
  e.sample = sample;
  ++end_seq_;
  return e;
}

std::optional<std::uint64_t> StateHistory::find_at_or_before(double t_s) const {
  // Times in the ring increase strictly: binary search for the last entry with time <= t_s.
  std::uint64_t lo = oldest_seq(), hi = end_seq_;
  if (lo == hi || at(lo).sample.t_s > t_s) return std::nullopt;
  while (hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    if (at(mid).sample.t_s <= t_s) lo = mid; else hi = mid;
  }
  return lo;
}

const StateEntry* StateHistory::base_at_or_before(double t_s, std::optional<std::uint64_t> k) const {
  const StateEntry* base = nullptr;
  if (k && *k >= first_state_seq_) base = &at(*k);
  if (anchor_valid_ && anchor_.sample.t_s <= t_s && anchor_.sample.t_s >= evicted_t_s_ &&
      (!base || anchor_.sample.t_s >= base->sample.t_s))
    base = &anchor_;
  return base;
}

const StateEntry* StateHistory::newest_state() const {
  const StateEntry* entry = nullptr;
  if (!ring_.empty() && end_seq_ - 1 >= first_state_seq_) entry = &ring_.newest();
  if (anchor_valid_ && (!entry || anchor_.sample.t_s >= entry->sample.t_s)) entry = &anchor_;
  return entry;
}

}  // namespace epichead::fusion
