/** @file OutlierGate.h
 *  @brief χ² innovation gate and robust-loss weights for scalar updates (docs/math/filter.md F11, F13).
 */
#pragma once

#include "uwb/filter/EkfParams.h"

namespace uwb {

/// Outcome of one measurement update (STYLE §8: expected runtime events are values).
enum class UpdateOutcome { kApplied, kRejectedOutlier, kDegenerate, kUnknownAnchor, kSkipped };

/// Mahalanobis gate on a scalar innovation: accept iff NIS = r²/S ≤ gate_sigma² (χ²₁ quantile; F11).
class OutlierGate {
 public:
  explicit OutlierGate(double gate_sigma) : threshold_(gate_sigma * gate_sigma) {}
  bool accept(double nis) const { return nis <= threshold_; }
  double threshold() const { return threshold_; }

 private:
  double threshold_;
};

/// IRLS weight w(e) = ρ'(e)/e of the robust loss at the normalised residual e (F13):
/// none: 1; Huber: min(1, k/|e|); Cauchy: 1/(1 + (e/k)²).
double robustWeight(RobustLoss loss, double e, double k);

/// Iteratively reweighted scalar update (F13): the weight w that solves the fixed point
///   w = robustWeight(e),  e = r_post/σ,  r_post = r · (σ²/w) / (hph + σ²/w),
/// starting from w = 1, for `iterations` iterations. hph = H P Hᵀ, var = σ² [m²], r the prior innovation.
double robustUpdateWeight(RobustLoss loss, double k, double innovation_m, double hph_m2, double var_m2,
                          int iterations);

}  // namespace uwb
