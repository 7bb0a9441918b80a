/** @file TrajectoryMetrics.h
 *  @brief Position error of an estimated trajectory against ground truth: the estimate is interpolated at the
 *         ground-truth timestamps and the body origins are compared.
 *         RMSE per axis and 3D, 50/90/99 % percentiles, whole flight and airborne (io/Airborne.h).
 */
#pragma once

#include <cstddef>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/io/Airborne.h"
#include "uwb/io/Flight.h"
#include "uwb/io/TrajectoryCsv.h"

namespace uwb {

struct TrajectoryMetricsParams {
  double airborne_min_z_m = kAirborneMinZ_m;  ///< isAirborne threshold on the ground-truth body z [m]
  double max_interp_gap_s = 0.1;              ///< no comparison where estimate samples are farther apart [s]
  void validate() const;
};

/// Error statistics over a set of samples (NaN-free; zero counts give zeros).
struct PositionErrorStats {
  std::size_t n = 0;
  Vec3 rmse_axis_m = Vec3::Zero();  ///< per world axis
  double rmse_m = 0.0;              ///< 3D
  double mean_m = 0.0;              ///< mean 3D error
  double p50_m = 0.0, p90_m = 0.0, p99_m = 0.0, max_m = 0.0;  ///< percentiles of the 3D error
};

/// One compared instant (for error-distribution plots).
struct PositionErrorSample {
  double t_s = 0.0;
  Vec3 w_p_true = Vec3::Zero();
  Vec3 w_p_est = Vec3::Zero();
  Vec3 error_m = Vec3::Zero();  ///< est − true
  double error_norm_m = 0.0;
  bool airborne = false;
};

struct TrajectoryMetrics {
  PositionErrorStats whole;
  PositionErrorStats airborne;
  std::vector<PositionErrorSample> samples;
  std::size_t n_truth_not_covered = 0;  ///< ground-truth samples outside the estimate (not compared)
};

/// Statistics of a list of error samples (percentiles by linear interpolation of the sorted errors).
PositionErrorStats positionErrorStats(const std::vector<PositionErrorSample>& samples, bool airborne_only);

/// RMSE of the airborne samples of `m` with t0_s ≤ t ≤ t1_s (a window of the flight; NaN when there are none).
double airborneRmseInWindow(const TrajectoryMetrics& m, double t0_s, double t1_s);

/// Interpolates `estimate` (sorted by time) at each ground-truth time (io/PoseTrack.h interpolatePose, position
/// only) and compares body origins.
/// `truth` should be glitch-free (e.g. PoseTrack::samples()).
TrajectoryMetrics computeTrajectoryMetrics(const Trajectory& estimate, const std::vector<PoseSample>& truth,
                                           const TrajectoryMetricsParams& params = {});

}  // namespace uwb
