/** @file EstimateChecks.h
 *  @brief What the generalization protocol checks on a localized flight besides the RMSE: whether the reported
 *         σ means what it says (per-axis coverage of the 1σ/2σ bands, docs/math/filter.md F23), the largest step
 *         between consecutive airborne outputs, estimates below the floor or above the arena once on the ground,
 *         and how fast the error settles after the start.
 */
#pragma once

#include <limits>

#include "uwb/eval/TrajectoryMetrics.h"
#include "uwb/io/TrajectoryCsv.h"

namespace uwb {

struct EstimateCheckParams {
  double floor_z_m = 0.0;           ///< floor height [m]
  double floor_tolerance_m = 0.1;   ///< below floor − this is a violation [m]
  double ceiling_z_m = std::numeric_limits<double>::infinity();  ///< arena top (e.g. the highest anchor) [m]
  double settle_error_m = 0.3;      ///< "settled": error at or below this [m]
  double step_max_dt_s = 0.05;      ///< steps are measured between outputs at most this far apart [s]
  /// Start of the log (e.g. the first TDoA) for the early-error window; NaN: the first estimate [s]
  double t_start_s = std::numeric_limits<double>::quiet_NaN();
};

struct EstimateChecks {
  Vec3 coverage_1sigma = Vec3::Zero();  ///< airborne fraction of |e_axis| ≤ σ_axis, per world axis
  Vec3 coverage_2sigma = Vec3::Zero();  ///< … ≤ 2σ_axis
  std::size_t n_coverage = 0;
  double max_airborne_step_m = 0.0;     ///< largest |p_k − p_{k−1}| between consecutive airborne outputs
  double min_z_on_ground_m = std::numeric_limits<double>::quiet_NaN();  ///< estimates while the truth is on the
  double max_z_on_ground_m = std::numeric_limits<double>::quiet_NaN();  ///< ground, after the first airborne one
  /// Largest error of the estimates before the first airborne one (on the ground before take-off; NaN: none)
  double max_error_before_takeoff_m = std::numeric_limits<double>::quiet_NaN();
  bool floor_or_ceiling_violated = false;
  double first_estimate_t_s = std::numeric_limits<double>::quiet_NaN();
  /// Time from the first estimate until the error stays ≤ settle_error_m for the rest of the airborne flight
  /// (NaN: never; 0: from the start).
  double settle_time_s = std::numeric_limits<double>::quiet_NaN();
  double max_error_after_3s_m = 0.0;    ///< largest airborne error later than 3 s after t_start_s
  double rmse_3_to_5s_m = std::numeric_limits<double>::quiet_NaN();  ///< airborne RMSE over [t_start + 3, + 5] s
};

/// The checks of `estimate` against the compared samples of computeTrajectoryMetrics (metrics.samples).
EstimateChecks checkEstimate(const Trajectory& estimate, const TrajectoryMetrics& metrics,
                             const EstimateCheckParams& params = {});

}  // namespace uwb
