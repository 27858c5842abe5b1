#pragma once
// Online estimate of one joint's gear backlash, for a head whose play was not calibrated (or
// has grown since). The encoder is on the motor and the gyro on the camera, which the output
// shaft carries: after the motor reverses, the output rests while the motor crosses the dead
// band, then moves with it again. Measured per reversal, from the motor's extreme: the motor's
// travel less the output's at the first encoder reading after the output has moved the new way
// by engaged_rad (it reached the far edge) is the band. The output's travel is the camera's
// rotation about the joint (the gyro's x/y rate in joint space, integrated) less the body's,
// taken as turning at the rate it had at the extreme over the crossing's tens of milliseconds.
//
// A reversal gives a sample only when the output sat on the band's edge at the extreme (it moved
// with the motor on the leg before), the body was quiet (|rate about the joint| at most
// quiet_body_radps: inside a walking step's burst the held rate says nothing about the next
// milliseconds), the crossing took at most max_crossing_s, the sample is within [0, max_rad],
// and the band measured at the next readings does not grow by more than confirm_tolerance_rad
// within confirm_s (else the output's "arrival" was the body's turning); the others are counted
// as rejected. The estimate is the median of the last `window` samples. Fixed storage, no
// allocation.
#include <array>
#include <cstdint>

namespace epichead::head {

struct BacklashEstimateOptions {
  bool enabled = true;
  // The bound: a sample above this is rejected (no pan/tilt gear of this class has 10 mrad of
  // play; a larger figure is a slipping clamp or body motion the leg could not separate).
  double max_rad = 0.01;
  // The motor must come back this far from its extreme before a reversal is taken (two encoder
  // steps of 1e-4 rad: one step back and forth is the encoder's rounding, not a reversal).
  double reversal_rad = 2e-4;
  // The output has moved this far the new way: it reached the far edge. Above the gyro's noise
  // and bias integrated over a crossing (tens of microradians).
  double engaged_rad = 1.5e-4;
  double max_crossing_s = 0.1;          // a longer crossing is not measured: the body's rate is held over it
  double quiet_body_radps = 0.02;       // the body turns slower than this about the joint: a sample may be taken
  double confirm_s = 0.015;             // the band must hold this long after the crossing (or until the next reversal)
  double confirm_tolerance_rad = 1.5e-4;  // by this much: two readings' rounding and a little
  double max_reading_gap_s = 0.02;      // encoder readings further apart (a silent head) restart the leg
  int window = 15;       // samples the median is taken over (1..kMaxWindow)
  int min_samples = 5;   // no estimate before this many
  // The compensation gets this fraction of the estimate: a band taken too wide costs far more
  // than one too narrow (the model then holds the output still while it already turns, and the
  // gyro's rate is fed back as body rate; docs/head.md section 5), and the median of a window of
  // samples still scatters by several percent.
  double applied_fraction = 0.85;
  // An estimate below this is taken as no play at all: two encoder steps of rounding.
  double min_applied_rad = 2e-4;
};

class BacklashEstimator {
 public:
  static constexpr int kMaxWindow = 31;

  explicit BacklashEstimator(const BacklashEstimateOptions& options = {});

  // A gyro sample: the camera's rotation rate about this joint (the joint-space share of the
  // gyro's x/y rate) over the dt_s since the previous one.
  void camera_rate(double joint_rate_radps, double dt_s);
  // An encoder reading of the motor angle at t_s (after the gyro samples up to t_s), with the
  // body's rate about the joint now (the gyro's less the joints' own).
  void motor_angle(double t_s, double motor_rad, double body_joint_rate_radps);
  // Forget the leg in progress (a gap in the gyro, a restart of the commands); samples stay.
  void restart_leg();

  bool has_estimate() const { return count_ >= options_.min_samples; }
  // The median of the recent samples (0 before has_estimate()).
  double estimate_rad() const { return estimate_rad_; }
  // The band for the compensation: the calibrated one (calibrated_rad, 0 when not told), or
  // applied_fraction of the estimate when that is wider. Gear play grows with wear and is never
  // less than measured on the assembled head, so the estimate only ever widens the calibration.
  double band_rad(double calibrated_rad) const;
  std::uint64_t samples() const { return accepted_; }
  std::uint64_t rejected() const { return rejected_; }

 private:
  // A motor reading with the camera's joint-space angle and the body's rate about the joint then.
  struct Reading {
    double t_s = 0, motor_rad = 0, camera_rad = 0, body_radps = 0;
  };
  // Where the crossing of the leg in progress stands at `now`: ends it (engaged) or confirms
  // the sample it gave.
  void follow_crossing(const Reading& now);
  void settle_pending(bool confirmed);
  void take_sample(double band_rad);

  BacklashEstimateOptions options_;
  double camera_rad_ = 0;  // the camera's joint-space angle: the integral of camera_rate()
  bool have_reading_ = false;
  double previous_t_s_ = 0;
  // The leg in progress: where it started (the extreme the motor turned at), its extreme so far,
  // the motor's direction on it (+1 / -1, 0: not yet known).
  Reading leg_, extreme_;
  int direction_ = 0;
  bool leg_engaged_ = false;      // the output has moved with the motor on this leg
  bool leg_from_edge_ = false;    // and did on the previous one: the output sat on the edge
  bool pending_ = false;          // a sample from this leg's crossing, not yet confirmed
  double pending_rad_ = 0, pending_t_s_ = 0;
  std::array<double, kMaxWindow> recent_{};
  int count_ = 0, next_ = 0;
  double estimate_rad_ = 0;
  std::uint64_t accepted_ = 0, rejected_ = 0;
};

}  // namespace epichead::head
