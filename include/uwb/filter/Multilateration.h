/** @file Multilateration.h
 *  @brief Start without ground truth: robust Gauss–Newton TDoA multilateration of a position from a batch of
 *         measurements taken while the body moved by known displacements (docs/math/filter.md F16).
 */
#pragma once

#include <optional>
#include <vector>

#include "uwb/filter/TdoaUpdate.h"

namespace uwb {

/// One measurement of the batch: the TDoA and the body displacement d_i since the reference instant, so the body
/// was at p0 + d_i when it was taken (d_i from IMU integration; zero for a static body).
struct MultilaterationSample {
  TdoaObservation z;
  Vec3 w_d_b = Vec3::Zero();
  Quat w_q_b = Quat::Identity();  ///< attitude when measured (lever arm)
};

struct MultilaterationResult {
  Vec3 w_p0 = Vec3::Zero();         ///< body origin at the reference instant [m]
  Mat3 covariance = Mat3::Identity();  ///< (JᵀWJ)⁻¹ σ̂² [m²]
  double rms_residual_m = 0.0;      ///< robustly weighted RMS residual
  int iterations = 0;
  std::size_t n_used = 0;
};

/// Huber-IRLS Gauss–Newton on p0 (F16), started from each of `initial_guesses`; returns the lowest-cost solution,
/// or nullopt when fewer than 4 usable samples or no start converges.
std::optional<MultilaterationResult> multilaterate(const std::vector<MultilaterationSample>& samples,
                                                   const AnchorTable& anchors, const Vec3& b_t_tag,
                                                   const std::vector<Vec3>& initial_guesses,
                                                   double huber_k_m = 0.3, int max_iterations = 30);

}  // namespace uwb
