#pragma once
// The controller's watchdog: from the age of the newest gyro sample, head state and target
// observation and the bus state it raises faults at once and clears them only after the input
// has been good for a recovery time (hysteresis, so a flickering input does not make the head
// switch modes every tick). Pure: time comes in with the input.
#include "epichead/head/control_mode.h"

namespace epichead::head {

struct WatchdogOptions {
  double imu_timeout_s = 0.010;         // 10 missed 1 kHz samples: ImuStale
  double imu_recover_s = 0.050;         // samples fresh this long: ImuStale clears
  double head_state_timeout_s = 0.020;  // no head state this long: HeadStateStale
  double head_state_recover_s = 0.050;
  double bus_recover_s = 0.050;         // bus not off this long: BusOff clears
  double target_timeout_s = 0.25;       // no valid target this long while fixating: TargetLost (about 7 frames at 30 fps)
  double lost_to_hold_s = 2.0;          // TargetLost this long: Fixate falls back from Stabilise to Hold
};

struct WatchdogInput {
  double t_s = 0;
  bool have_gyro = false;       // any sample so far
  double last_gyro_t_s = 0;     // program time of the newest accepted gyro sample
  bool have_head_state = false;
  double last_head_state_t_s = 0;
  bool bus_off = false;
  bool fixating = false;        // the caller wants Fixate: only then is a missing target a fault
  bool have_target = false;
  double last_target_t_s = 0;   // newest valid target observation (its arrival, program time)
};

struct FaultChange {
  Fault raised = Fault::None, cleared = Fault::None;
};

class Watchdog {
 public:
  explicit Watchdog(const WatchdogOptions& options = {}) : options_(options) {}
  FaultChange update(const WatchdogInput& in);
  Fault faults() const { return faults_; }
  // When the target was lost (valid while TargetLost is set).
  double target_lost_since_s() const { return lost_since_s_; }
  const WatchdogOptions& options() const { return options_; }

 private:
  // One input's fault with hysteresis; `ok_since` is when the input last turned good.
  struct Channel {
    bool was_bad = true;
    double ok_since_s = 0;
  };
  bool step(Channel& c, Fault f, bool bad_now, double t_s, double recover_s, FaultChange& change);

  WatchdogOptions options_;
  Fault faults_ = Fault::None;
  Channel imu_, head_, bus_;
  double lost_since_s_ = 0;
};

}  // namespace epichead::head
