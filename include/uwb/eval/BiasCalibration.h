/** @file BiasCalibration.h
 *  @brief Calibration of the predicted TDoA bias on a flight: does ε fall inside the predicted intervals as often
 *         as they claim, and how likely is it under the predictive density (docs/math/gp.md P43).
 *
 *  For every sample with a covering GP: r = ε − µ, σ² = var_f + σ_n² (BiasModel::predictive), z = |r| / σ, and the
 *  predictive distribution of r of the model's shape (P43b): a Student-t with ν degrees of freedom and scale κσ, or
 *  for ν = 0 the Gaussian N(0, κ²σ²). With w(p) the half-width of its central interval of probability p, in units of σ:
 *    coverage(p)  = #{z ≤ w(p)} / n                     (central interval of nominal probability p)
 *    coverage_1σ  = coverage(0.6827),  coverage_2σ = coverage(0.9545)   (the Gaussian's ±1σ and ±2σ masses)
 *    NLPD         = −(1/n) Σ log p(r)                    [nats per sample; lower is better]
 *  For the Gaussian shape with κ = 1 these are the plain ±σ, ±2σ intervals and ½ [log(2π σ²) + r²/σ²].
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
/// (P43b) The half-width, in units of σ, of the central interval of probability p of the shape: κ t_ν⁻¹((1 + p)/2), or
/// κ Φ⁻¹((1 + p)/2) for ν = 0. Throws std::invalid_argument for p outside (0, 1) or an invalid shape.
double centralIntervalHalfWidth(double p, const PredictiveShape& shape);
/// (P43b) log p(r) of the shape's predictive density with σ² = variance_m2 > 0 [log 1/m].
double predictiveLogDensity(double r_m, double variance_m2, const PredictiveShape& shape);

/// Probability mass of the Gaussian within ±1σ and ±2σ: the nominal levels of coverage_1σ and coverage_2σ.
inline constexpr double kOneSigmaMass = 0.682689492137086, kTwoSigmaMass = 0.954499736103642;

struct BiasCalibration {
  std::size_t n = 0;            ///< samples with a covering GP
  std::size_t n_uncovered = 0;  ///< samples of pairs no GP covers (left out)
  double coverage_1sigma = 0.0;  ///< fraction with |r| ≤ σ (nominal 0.6827)
  double coverage_2sigma = 0.0;  ///< fraction with |r| ≤ 2σ (nominal 0.9545)
  double nlpd = 0.0;             ///< mean negative log predictive density [nats]
  double rmse_m = 0.0;           ///< RMS of r
  double mean_std_m = 0.0;       ///< mean predictive σ
  std::vector<double> coverage;  ///< at calibrationLevels()
  PredictiveShape shape = PredictiveShape::gaussian();  ///< the predictive distribution scored (P43b)
};

/// Scores r = ε − µ against σ² = var_f + σ_n² + the level excess of the sample's flight (P43c, from the level the
/// dataset's filter run measured; none for ground-truth inputs) over the dataset's samples (features as stored in the
/// dataset), with the model's predictive shape.
BiasCalibration biasCalibration(const BiasDataset& data, const BiasModel& model);

/// From residuals and predictive variances directly (same definitions), for the given shape (default: Gaussian).
BiasCalibration biasCalibration(const std::vector<double>& residual_m, const std::vector<double>& variance_m2,
                                const PredictiveShape& shape = PredictiveShape::gaussian());

/// {"n", "n_uncovered", "coverage_1sigma", "coverage_2sigma", "nlpd", "rmse_m", "mean_std_m", "levels", "coverage",
///  "predictive_dof", "predictive_scale"}
nlohmann::json toJson(const BiasCalibration& c);

}  // namespace uwb
