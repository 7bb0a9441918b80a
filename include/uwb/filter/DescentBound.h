/** @file DescentBound.h
 *  @brief Upper bound on the height while landing, from the IMU alone (docs/math/filter.md F26).
 *
 *  Near the floor the TDoA carry the floor-level bias (F14): on a touchdown that the estimate has not followed yet
 *  they pull the estimate up, metres within a second, until the IMU shows the rest or the floor contact (F18). The
 *  vertical motion integrated from the accelerometer since the estimate was last well above the floor does not
 *  climb; the estimate may not rise more than a margin above it. The bound exists only for a short while after a
 *  descent through the reset height and only while the dead-reckoned height is low; it is one-sided (it never lifts
 *  the estimate) and it is re-derived at every check, so nothing it decides outlives the evidence.
 */
#pragma once

#include <limits>

namespace uwb {

struct DescentBoundParams {
  double margin_m = 0.3;          ///< the estimate may rise this far above the dead-reckoned height [m]
  double band_m = 0.4;            ///< bound only while the dead-reckoned height above the floor is below this [m]
  double reset_height_m = 0.75;   ///< dead reckoning restarts from the estimate while it is this high [m]
  double max_age_s = 2.5;         ///< … and is used at most this long after its last restart [s]
};

class DescentBound {
 public:
  explicit DescentBound(const DescentBoundParams& params = {}) : params_(params) {}

  /// No dead reckoning (on the ground, after a take-off, a time jump or a re-acquisition).
  void clear() { valid_ = false; }
  /// One IMU step: vertical acceleration a_up = (R f)_z − g_ref [m/s²] over dt_s (F26).
  void integrate(double a_up_mps2, double dt_s);
  /// At a check at t_s with the estimate's height above the floor h_est and vertical velocity: restarts the dead
  /// reckoning from the estimate while both are above their thresholds; returns the bound on the height above the
  /// floor, or NaN when there is none.
  double update(double t_s, double h_est_m, double vz_est_mps);

  /// Dead-reckoned height above the floor and vertical velocity (meaningful while a dead reckoning runs).
  double height() const { return h_m_; }
  double verticalVelocity() const { return v_mps_; }
  bool running() const { return valid_; }

 private:
  DescentBoundParams params_;
  bool valid_ = false;
  double h_m_ = 0.0, v_mps_ = 0.0;
  double t_restart_s_ = -std::numeric_limits<double>::infinity();
};

}  // namespace uwb
