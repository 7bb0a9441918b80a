/** @file TofUpdate.h
 *  @brief Downward time-of-flight range (Flow deck VL53L1x) as a scalar height update of the filter, the way
 *         Crazyflie's kalman_core does it (kalmanCoreUpdateWithTof; Mueller, Hamer, D'Andrea, ICRA 2015), with
 *         the sensor's lever arm and the attitude part of the Jacobian. docs/math/filter.md F21.
 */
#pragma once

#include <optional>

#include "uwb/filter/Ekf.h"
#include "uwb/filter/OutlierGate.h"

namespace uwb {

/// One ToF range sample [s], [m] (distance along the sensor's axis, the body −z axis).
struct TofObservation {
  double t_s = 0.0;
  double range_m = 0.0;
};

/// Below this cos(tilt) = R33 the ray misses a flat floor in a useful way (Crazyflie: R33 > 0.1); no update.
constexpr double kTofMinCosTilt = 0.1;

/// (F21) Predicted ToF range to the flat floor z = floor_z_m along the body −z axis from the sensor at
/// b_t_s = (0, 0, −offset_m):  h = (p_z − floor_z) / R33 − offset_m,  R33 = e3ᵀ R(w_q_b) e3.
/// Fills J_h_dx (∂h/∂δx, error state of StateIndex.h, right attitude error) if non-null; nullopt when
/// R33 ≤ kTofMinCosTilt (sensor not facing the floor).
std::optional<double> tofPredictedRange(const NavState& x, double offset_m, double floor_z_m,
                                        ErrRow* J_h_dx = nullptr);

/// (F21) The body's height above the floor z = floor_z_m that a range measures at attitude w_q_b, the inverse of
/// tofPredictedRange: p_z − floor_z = (range + offset_m)·R33; nullopt when R33 ≤ kTofMinCosTilt.
std::optional<double> tofMeasuredHeight(const Quat& w_q_b, double range_m, double offset_m);

struct TofUpdateOptions {
  double sigma_m = 0.03;       ///< range noise std [m]
  double offset_m = 0.037;     ///< sensor below the body origin along body z [m]
  double floor_z_m = 0.0;      ///< floor height in the world frame [m]
  double max_range_m = 3.5;    ///< readings above this (or ≤ 0, non-finite) are invalid
  double gate_sigma = 4.0;     ///< χ² gate on √NIS (F11); ≤ 0 disables
};

struct TofUpdateResult {
  UpdateOutcome outcome = UpdateOutcome::kSkipped;  ///< kSkipped: invalid reading; kDegenerate: too tilted
  double innovation_m = 0.0;  ///< z − h(x̂)
  double nis = 0.0;
};

/// Full ToF update of `ekf` (F21, gate F11, reset F8). The covariance should be propagated by the caller.
TofUpdateResult updateTof(Ekf& ekf, double range_m, const TofUpdateOptions& options);

}  // namespace uwb
