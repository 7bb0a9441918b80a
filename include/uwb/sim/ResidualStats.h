/** @file ResidualStats.h
 *  @brief TDoA residual statistics against a pose stream (measured − model at the interpolated pose):
 *  median, mean absolute deviation, per-pair medians, autocorrelation. Used to compare simulated and real flights.
 */
#pragma once

#include <map>
#include <utility>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"

namespace uwb::sim {

struct PairResidualStats {
  std::size_t count = 0;
  double median_m = 0.0;
  double std_m = 0.0;
};

struct ResidualStats {
  std::size_t count = 0;            ///< residuals in the selection
  double median_m = 0.0;
  double mean_abs_dev_m = 0.0;      ///< mean |r − median|
  double std_m = 0.0;
  double outlier_fraction = 0.0;    ///< |r − pair median| > 1 m
  std::map<std::pair<int, int>, PairResidualStats> pairs;
  /// Mean over pairs of the lag autocorrelation of each pair's residual series, for lags 0.1, 0.3, 1, 5 s.
  std::vector<std::pair<double, double>> autocorrelation;
};

enum class Phase { kAirborne, kGround, kAll };

/// Residual r = tdoa − (|p_tag − a_B| − |p_tag − a_A|) with the pose linearly interpolated (position) and the
/// earlier sample's orientation; airborne = interpolated body z ≥ min_height_m (ground z + 0.3 m by convention,
/// z is measured in the world frame). Measurements outside the pose time span are skipped.
ResidualStats residualStats(const Flight& flight, const AnchorSurvey& survey, Phase phase,
                            double airborne_min_z_m = 0.3, const Vec3& b_t_tag = kUtilTagOffset_b);

}  // namespace uwb::sim
