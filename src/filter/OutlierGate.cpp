/** @file OutlierGate.cpp
 *  @brief Robust-loss weights and the IRLS fixed point of a scalar update (docs/math/filter.md F13).
 */
#include "uwb/filter/OutlierGate.h"

#include <algorithm>
#include <cmath>

namespace uwb {

double robustWeight(RobustLoss loss, double e, double k) {
  const double a = std::abs(e);
  switch (loss) {
    case RobustLoss::kNone: return 1.0;
    case RobustLoss::kHuber: return a <= k ? 1.0 : k / a;
    case RobustLoss::kCauchy: return 1.0 / (1.0 + (e / k) * (e / k));
  }
  return 1.0;
}

double robustUpdateWeight(RobustLoss loss, double k, double innovation_m, double hph_m2, double var_m2,
                          int iterations) {
  if (loss == RobustLoss::kNone) return 1.0;
  const double sigma = std::sqrt(var_m2);
  double w = 1.0;
  for (int it = 0; it < iterations; ++it) {
    // (F13) posterior residual of the linearised problem with the current weight
    const double var_w = var_m2 / w;
    const double r_post = innovation_m * var_w / (hph_m2 + var_w);
    const double w_next = std::max(robustWeight(loss, r_post / sigma, k), 1e-6);
    if (w_next == w) break;  // fixed point reached: further iterations repeat the same arithmetic
    w = w_next;
  }
  return w;
}

}  // namespace uwb
