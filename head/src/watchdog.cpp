#include "epichead/head/watchdog.h"

namespace epichead::head {

bool Watchdog::step(Channel& c, Fault f, bool bad_now, double t_s, double recover_s, FaultChange& change) {
  if (bad_now) {
    c.was_bad = true;
    if (!has(faults_, f)) {
      faults_ = faults_ | f;
      change.raised = change.raised | f;
    }
    return true;
  }
  if (c.was_bad) {
    c.was_bad = false;
    c.ok_since_s = t_s;
  }
  if (has(faults_, f) && t_s - c.ok_since_s >= recover_s) {
    faults_ = faults_ & ~f;
    change.cleared = change.cleared | f;
  }
  return has(faults_, f);
}

FaultChange Watchdog::update(const WatchdogInput& in) {
  FaultChange change;
  const double t = in.t_s;
  const bool imu_bad = !in.have_gyro || !(t - in.last_gyro_t_s <= options_.imu_timeout_s);
  step(imu_, Fault::ImuStale, imu_bad, t, options_.imu_recover_s, change);
  // Before the first head state the controller is in Startup and commands nothing; the head
  // state only becomes a fault once it has been seen and then stops.
  const bool head_bad = in.have_head_state && !(t - in.last_head_state_t_s <= options_.head_state_timeout_s);
  step(head_, Fault::HeadStateStale, head_bad, t, options_.head_state_recover_s, change);
  step(bus_, Fault::BusOff, in.bus_off, t, options_.bus_recover_s, change);
  // A target is good again as soon as one valid observation arrives (no hysteresis: vision
  // already needs a whole frame, and waiting would only delay fixation).
  const bool lost = in.fixating && (!in.have_target || !(t - in.last_target_t_s <= options_.target_timeout_s));
  if (lost && !has(faults_, Fault::TargetLost)) {
    faults_ = faults_ | Fault::TargetLost;
    change.raised = change.raised | Fault::TargetLost;
    lost_since_s_ = t;
  } else if (!lost && has(faults_, Fault::TargetLost)) {
    faults_ = faults_ & ~Fault::TargetLost;
    change.cleared = change.cleared | Fault::TargetLost;
  }
  return change;
}

}  // namespace epichead::head
