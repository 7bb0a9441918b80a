/** @file TdoaFeature.h
 *  @brief What the bias model sees of one TDoA measurement, and the bias-predictor interface the filter takes.
 *
 *  The filter knows nothing of GPs (STYLE §1): it takes a BiasPredictor, a plain callable
 *  feature → (mean, variance) of the TDoA bias. Features are computed from a pose: the ground truth when
 *  training (paper eq. 6), the filter's estimate at run time (paper III-B). docs/math.md (M10–M11).
 */
#pragma once

#include <functional>

#include "uwb/core/Types.h"

namespace uwb {

/// GP inputs of one TDoA measurement between anchors A (id_a) and B (id_b), tdoa = |p − a_B| − |p − a_A|.
struct TdoaFeature {
  int id_a = 0;
  int id_b = 0;
  Vec3 b_p_a = Vec3::Zero();  ///< anchor A relative to the body origin, in the body frame [m] (x_kA of eq. 9)
  Vec3 b_p_b = Vec3::Zero();  ///< anchor B relative to the body origin, in the body frame [m] (x_kB of eq. 9)
  double yaw_a_rad = 0.0;     ///< azimuth of anchor A in the body frame, atan2(y, x) ∈ (−π, π] (α of eq. 7)
  double yaw_b_rad = 0.0;     ///< azimuth of anchor B in the body frame
  Vec3 w_p_b = Vec3::Zero();  ///< body origin in the world frame [m]
  Vec3 w_p_anchor_a = Vec3::Zero();  ///< anchor A in the world frame [m] (identifies the anchor; bias-model inputs)
  Vec3 w_p_anchor_b = Vec3::Zero();  ///< anchor B in the world frame [m]
};

/// Builds the feature from a pose (w_p_b, w_q_b) and the world positions of anchors A and B.
TdoaFeature makeTdoaFeature(int id_a, int id_b, const Vec3& w_p_b, const Quat& w_q_b, const Vec3& w_p_anchor_a,
                            const Vec3& w_p_anchor_b);

/// Predicted TDoA bias: mean [m] and variance [m²]; the corrected measurement is z − mean, its variance
/// noise_scale · σ_tdoa² + variance_m2 (σ_tdoa² the filter's own TDoA variance). noise_scale = 1: the paper's
/// R + var_f; a model that predicts how much of the error it leaves unexplained scales R by it (docs/math/gp.md P45).
struct BiasPrediction {
  double mean_m = 0.0;
  double variance_m2 = 0.0;
  double noise_scale = 1.0;  ///< factor (> 0) on the filter's TDoA variance for the corrected measurement
};

/// feature → predicted bias. Must be cheap (called once per TDoA update) and thread-compatible.
using BiasPredictor = std::function<BiasPrediction(const TdoaFeature&)>;

}  // namespace uwb
