/** @file RestDetector.h
 *  @brief Is the body at rest (motors off, not carried), or does it shake as a quadrotor does that sits on the floor
 *         with its motors running? Exponential moving statistics of the IMU, re-evaluated at every sample, so the
 *         answer is revised as soon as the IMU contradicts it (docs/math/filter.md F18).
 *
 *  The estimator uses both as evidence for zero-velocity updates and for down-weighting TDoA near the floor. A still
 *  hover is not rest (the motors' vibration keeps the accelerometer variance far above the threshold) and does not
 *  shake like ground contact (the 8 Hz high-passed gyro rms in flight is 0.04–0.05 rad/s median, against 0.22–0.25
 *  median on the floor with the motors running, util-pilot).
 */
#pragma once

#include "uwb/filter/NavState.h"

namespace uwb {

struct RestDetectorParams {
  double acc_std_mps2 = 0.12;   ///< rest: std of |specific force| below this [m/s²]
  double gyro_rms_radps = 0.03; ///< … and gyro rms below this [rad/s]
  double tau_s = 0.1;           ///< time constant of the moving statistics [s]
  double min_hold_s = 0.2;      ///< the rest test must hold this long before rest is reported [s]
  /// Ground contact: rms of the high-passed gyro above this [rad/s]. The high-pass removes a moving mean of time
  /// constant hp_tau_s (cut-off ≈ 8 Hz: manoeuvres pass below it, rotor-frame shaking above). In flight 99 % of the
  /// samples are below 0.114 (0425) and 0.106 (0426); on the floor with the motors running the median is 0.247 and
  /// 0.217, the lower quartile 0.153 and 0.122 (docs/math/filter.md F18).
  double contact_gyro_hp_rms_radps = 0.15;
  double hp_tau_s = 0.02;
  /// A gyro reference (the reading at rest: the gyro's own bias) is accepted only up to this norm [rad/s]; larger
  /// means the body was turning (F18).
  double max_gyro_reference_radps = 0.1;
};

class RestDetector {
 public:
  explicit RestDetector(const RestDetectorParams& params = {});
  /// Folds in one IMU sample taken dt_s after the previous one (F18). dt_s ≤ 0 only re-evaluates.
  void update(double t_s, const ImuReading& imu, double dt_s);
  /// At rest: the moving statistics have been below both thresholds for at least min_hold_s.
  bool atRest() const { return at_rest_; }
  /// The instantaneous test (no hold).
  bool stillNow() const;
  double accVariance() const { return acc_var_; }
  double gyroMeanSquare() const { return gyro_ms_; }
  /// The shaking of ground contact with the motors running: high-passed gyro rms above its threshold (F18).
  bool shaking() const { return gyro_hp_ms_ > contact_ms_min_; }
  /// The high-passed gyro mean square that shaking() tests [rad²/s²] (F18; its level in flight is learned, F29b).
  double gyroHighPassMeanSquare() const { return gyro_hp_ms_; }
  /// Restarts the statistics from a sample (moving, not at rest); a gyro reference is kept.
  void reset(const ImuReading& imu);
  /// (F18) Starts the moving statistics from a window's sample moments instead (the levelling window of F15): the
  /// variance of the specific force, the gyro's mean square, and its mean square about the gyro reference (used when
  /// one is set). A body still from its first sample then reads as at rest min_hold_s after t_s, not only once the
  /// statistics of reset() have decayed (≈ 0.7 s), so the start's first fix (after ≥ 0.6 s of TDoA) finds it on the
  /// ground. Call after reset() and setGyroReference(). Moments that are not finite or negative are ignored.
  void seed(double t_s, double acc_var_mps2sq, double gyro_ms_radps2sq, double gyro_ref_ms_radps2sq);
  /// (F18) The gyro's reading at rest (its bias, e.g. the mean of a still levelling window): the gyro test then passes
  /// when either the raw rate or its deviation from this reference is small, so that an uncalibrated gyro still reads
  /// as at rest and a wrong reference costs nothing. Returns false (and keeps none) above max_gyro_reference_radps.
  bool setGyroReference(const Vec3& b_gyro_radps);
  bool hasGyroReference() const { return has_gyro_ref_; }

 private:
  RestDetectorParams params_;
  double acc_var_max_, gyro_ms_max_, rate_per_s_, hp_rate_per_s_, contact_ms_min_;
  double acc_mean_ = 9.81, acc_var_ = 1.0, gyro_ms_ = 1.0, gyro_hp_ms_ = 0.0;
  double gyro_ref_ms_ = 1.0;  ///< mean square of the gyro's deviation from the reference
  Vec3 gyro_ref_ = Vec3::Zero();
  bool has_gyro_ref_ = false;
  Vec3 gyro_mean_ = Vec3::Zero();
  /// The decay factors of the last Δt: the IMU period repeats, so they are recomputed only when it changes.
  double dt_cached_s_ = -1.0, a_cached_ = 0.0, a_hp_cached_ = 0.0;
  double t_still_since_ = 0.0;
  bool still_ = false;
  bool at_rest_ = false;
};

/// exp(−x) for x ≥ 0 at the accuracy of std::exp, cheap for the per-IMU-sample decay factors exp(−Δt/τ) (x < 0.1:
/// Taylor series to x⁹ in Estrin's scheme; successor term below 3e-17).
double expNegative(double x);

}  // namespace uwb
