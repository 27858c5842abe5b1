#pragma once
// The IMU filter's memory of the last buffer_s: each IMU sample (camera clock) with the filter
// state right after it, in a fixed ring (a new sample overwrites the oldest), plus the anchor,
// the state right after the last vision pose at its exposure time (between two samples). A late
// pose is applied at its time from the state found here, then the later samples are
// re-propagated from the anchor. Samples are numbered in arrival order (seq); those from
// first_state_seq() on carry a state, older ones only their reading (kept for the gravity
// average and re-propagation). Sized once; nothing allocates after construction.
#include <cstddef>
#include <cstdint>
#include <optional>

#include "epichead/common/ring_buffer.h"
#include "epichead/fusion/imu_sample.h"
#include "epichead/fusion/nav_state.h"

namespace epichead::fusion {

// One sample and the filter state right after it.
struct StateEntry {
  ImuSample sample;
  NavState x;
  ErrorCovariance P;
};

class StateHistory {
 public:
  // capacity >= 2: a new entry never takes the newest one's slot.
  explicit StateHistory(std::size_t capacity) : ring_(capacity) {}

  bool empty() const { return ring_.empty(); }
  // Held entries are oldest_seq() .. end_seq() - 1.
  std::uint64_t oldest_seq() const { return end_seq_ - ring_.size(); }
  std::uint64_t end_seq() const { return end_seq_; }
  StateEntry& at(std::uint64_t seq) { return ring_[seq - oldest_seq()]; }
  const StateEntry& at(std::uint64_t seq) const { return ring_[seq - oldest_seq()]; }
  const ImuSample& newest_sample() const { return ring_.newest().sample; }  // precondition: !empty()

  // Appends `sample` as the newest entry, dropping the oldest when full (the anchor is unusable
  // before a dropped sample), and returns it. with_state: the caller fills in its state;
  // otherwise no entry up to it carries one.
  StateEntry& push(const ImuSample& sample, bool with_state);
  // The newest entry with sample time <= t_s; empty when none.
  std::optional<std::uint64_t> find_at_or_before(double t_s) const;
  // The latest state at or before t_s to step from: the entry `k` (find_at_or_before(t_s)) if it
  // carries a state, or the anchor when it is later and not older than the dropped samples.
  const StateEntry* base_at_or_before(double t_s, std::optional<std::uint64_t> k) const;
  // The newest state: the newest entry carrying one or the anchor, whichever is later; null when
  // there is neither.
  const StateEntry* newest_state() const;

  // The anchor; null when there is none.
  const StateEntry* anchor() const { return anchor_valid_ ? &anchor_ : nullptr; }
  // Sets the anchor (after a vision pose). The entries after it are the caller's to re-propagate.
  void set_anchor(const StateEntry& anchor) {
    anchor_ = anchor;
    anchor_valid_ = true;
  }
  // Entries from `seq` on carry a state (after an initialisation).
  void set_first_state_seq(std::uint64_t seq) { first_state_seq_ = seq; }
  std::uint64_t first_state_seq() const { return first_state_seq_; }

  // Forgets the anchor and every entry's state; the samples stay (for the next initialisation).
  void drop_states() {
    anchor_valid_ = false;
    first_state_seq_ = end_seq_;
  }
  // Forgets everything (a restarted device clock): samples, states, anchor, dropped times.
  void clear() {
    drop_states();
    ring_.clear();
    evicted_t_s_ = -1e300;
  }

 private:
  common::RingBuffer<StateEntry> ring_;
  std::uint64_t end_seq_ = 0;          // seq of the next sample
  std::uint64_t first_state_seq_ = 0;  // entries from here on carry a valid state
  StateEntry anchor_;
  bool anchor_valid_ = false;
  double evicted_t_s_ = -1e300;  // newest sample dropped from the ring: the anchor is unusable before it
};

}  // namespace epichead::fusion
