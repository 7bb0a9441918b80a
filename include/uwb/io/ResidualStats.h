/** @file ResidualStats.h
 *  @brief The statistics of a set of TDoA residuals (measured − model at the ground truth) used everywhere: by
 *         `uwbtdoa inspect` (eval/FlightSummary.h, per phase and pair) and by the simulator's comparison with real
 *         flights (sim/ResidualProfile.h).
 */
#pragma once

#include <cstddef>
#include <vector>

namespace uwb {

/// Residuals farther than this from their median are gross errors for ResidualStats::mad_m [m].
inline constexpr double kGrossResidual_m = 1.0;

/// Statistics of a set of residuals r_k [m]. The median and `mad_m` reproduce util-pilot/MANIFEST.csv
/// (resid_median_m, resid_mad_m; checked on all 17 flights to ≤ 0.001 m, docs/io.md "Residual statistics").
struct ResidualStats {
  std::size_t n = 0;
  double median_m = 0.0;  ///< median of all r_k
  /// Mean absolute deviation from the median over the residuals within kGrossResidual_m of it:
  /// mean_{k: |r_k − median| < 1 m} |r_k − median|. The MANIFEST's "mad" (gross errors, e.g. the ground phase
  /// or TDoA3 outliers, would otherwise dominate it).
  double mad_m = 0.0;
  std::size_t n_gross = 0;           ///< residuals excluded from mad_m (|r − median| ≥ kGrossResidual_m)
  double mean_abs_dev_m = 0.0;       ///< mean_k |r_k − median| over all residuals
  double median_abs_dev_m = 0.0;     ///< median_k |r_k − median| (the robust-statistics MAD, unscaled)
  double mean_m = 0.0;
  double std_m = 0.0;  ///< population standard deviation sqrt(mean_k (r_k − mean)²)
  double rms_m = 0.0;
};

/// Statistics of `values` (empty → all zero, n = 0).
ResidualStats residualStats(std::vector<double> values, double gross_residual_m = kGrossResidual_m);

}  // namespace uwb
