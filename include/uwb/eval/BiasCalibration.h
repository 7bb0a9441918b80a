/** @file BiasCalibration.h
 *  @brief Calibration of the predicted TDoA bias on a flight: does ε fall inside the predicted intervals as often
 *         as they claim, and how likely is it under the predictive density (docs/math/gp.md P43).
 *
 *  For every sample with a covering GP: r = ε − µ, σ² = var_f + σ_n² (BiasModel::predictive), z = |r| / σ.
 *    coverage(p)  = #{z ≤ Φ⁻¹((1 + p)/2)} / n          (central interval of nominal probability p)
 *    coverage_1σ  = #{z ≤ 1} / n  (nominal 68.27 %),  coverage_2σ = #{z ≤ 2} / n  (nominal 95.45 %)
 *    NLPD         = (1/n) Σ ½ [log(2π σ²) + r²/σ²]       [nats per sample; lower is better]
 */
#pragma once

#include <cstddef>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"

namespace uwb {

/// Nominal levels of the calibration curve: 0.05, 0.10, …, 0.95 and 0.99.
const std::vector<double>& calibrationLevels();

/// z such that P(|N(0, 1)| ≤ z) = p, for p in (0, 1). Throws std::invalid_argument outside.
double centralIntervalHalfWidth(double p);

struct BiasCalibration {
  std::size_t n = 0;            ///< samples with a covering GP
  std::size_t n_uncovered = 0;  ///< samples of pairs no GP covers (left out)
  double coverage_1sigma = 0.0;  ///< fraction with |r| ≤ σ (nominal 0.6827)
  double coverage_2sigma = 0.0;  ///< fraction with |r| ≤ 2σ (nominal 0.9545)
  double nlpd = 0.0;             ///< mean negative log predictive density [nats]
  double rmse_m = 0.0;           ///< RMS of r
  double mean_std_m = 0.0;       ///< mean predictive σ
  std::vector<double> coverage;  ///< at calibrationLevels()
};

/// Scores r = ε − µ against σ² = var_f + σ_n² over the dataset's samples (features as stored in the dataset).
BiasCalibration biasCalibration(const BiasDataset& data, const BiasModel& model);

/// From residuals and predictive variances directly (same definitions).
BiasCalibration biasCalibration(const std::vector<double>& residual_m, const std::vector<double>& variance_m2);

/// {"n", "n_uncovered", "coverage_1sigma", "coverage_2sigma", "nlpd", "rmse_m", "mean_std_m", "levels", "coverage"}
nlohmann::json toJson(const BiasCalibration& c);

}  // namespace uwb
