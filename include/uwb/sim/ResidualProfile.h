/** @file ResidualProfile.h
 *  @brief TDoA residuals of a flight against its pose stream, summarised to compare simulated and real flights:
 *  the residual statistics (io/ResidualStats.h) overall and per anchor pair, the share of gross errors and the
 *  residuals' autocorrelation over time.
 */
#pragma once

#include <map>
#include <utility>
#include <vector>

#include "uwb/io/Airborne.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"
#include "uwb/io/ResidualStats.h"

namespace uwb::sim {

struct ResidualProfile {
  ResidualStats overall;                           ///< all residuals of the phase
  double outlier_fraction = 0.0;                   ///< share with |r − pair median| > 1 m
  std::map<std::pair<int, int>, ResidualStats> pairs;  ///< per ordered anchor pair (id_a, id_b)
  /// Mean over pairs of the lag autocorrelation of each pair's residual series, for lags 0.1, 0.3, 1, 5 s.
  std::vector<std::pair<double, double>> autocorrelation;
};

enum class Phase { kAirborne, kGround, kAll };

/// Residuals r = tdoa − (|p_tag − a_B| − |p_tag − a_A|) at the ground-truth pose, computed by tdoaResiduals (sim/TdoaResiduals.h)
/// on the flight's PoseTrack (pose glitches excluded; position interpolated linearly and attitude by slerp, as
/// everywhere else); airborne = isAirborne(interpolated body z, airborne_min_z_m). Measurements without ground
/// truth or with an anchor missing from the survey are skipped.
ResidualProfile residualProfile(const Flight& flight, const AnchorSurvey& survey, Phase phase,
                                double airborne_min_z_m = kAirborneMinZ_m, const Vec3& b_t_tag = kUtilTagOffset_b);

/// Size of the floor-level TDoA bias (S18) against the height above the floor during the take-off: the median |r| of
/// the residuals (as in residualProfile) per height bin [edges[k], edges[k+1]), height = body z minus its first pose
/// z (the body at rest on the floor), over the TDoA before the body first rises top_m above the floor. Bins without
/// a residual report n = 0 and a NaN median.
struct HeightBin {
  double h0_m = 0.0, h1_m = 0.0;
  std::size_t n = 0;
  double median_abs_m = 0.0;
};
std::vector<HeightBin> takeoffResidualProfile(const Flight& flight, const AnchorSurvey& survey,
                                              const std::vector<double>& edges_m, double top_m = 0.8,
                                              const Vec3& b_t_tag = kUtilTagOffset_b);

}  // namespace uwb::sim
