/** @file TdoaLinearization.h
 *  @brief Linearized TDoA of the paper, eq. (3)–(4): ẑ_ij^k ≈ D + (B1 − B2) x_k − B1 x_i + B2 x_j
 *         (docs/math/measurement.md M6–M8).
 *
 *  Paper notation: z_ij^k = d_ki − d_kj = |x_k − x_i| − |x_k − x_j| (eq. 2).
 *  UTIL data convention tdoa = |p − a_B| − |p − a_A|  ⇒  call linearizeTdoa(x_k, x_i = a_B, x_j = a_A).
 */
#pragma once

#include <optional>

#include "uwb/core/Types.h"

namespace uwb {

/// B1 = d̃_kiᵀ/d̃_ki, B2 = d̃_kjᵀ/d̃_kj (1×3), D = d̃_ki − d̃_kj − B1 d̃_ki + B2 d̃_kj (scalar), with
/// d̃_ab = x̃_a − x̃_b and d̃_ab = |d̃_ab| (paper eq. 4; M7).
struct TdoaLinearization {
  RowVec3 B1 = RowVec3::Zero();
  RowVec3 B2 = RowVec3::Zero();
  double D = 0.0;
  /// B12 = B1 − B2, the multiplication node acting on x_k (paper Fig. 2).
  RowVec3 B12() const { return B1 - B2; }
  /// Affine model (M8): D + (B1 − B2) x_k − B1 x_i + B2 x_j.
  double evaluate(const Vec3& x_k, const Vec3& x_i, const Vec3& x_j) const {
    return D + (B1 - B2).dot(x_k) - B1.dot(x_i) + B2.dot(x_j);
  }
};

/// Linearization of eq. (4) at (x̃_k, x̃_i, x̃_j); exact at that point. nullopt when x̃_k is within
/// min_range_m of x̃_i or x̃_j (degenerate: gradient of the norm undefined).
std::optional<TdoaLinearization> linearizeTdoa(const Vec3& x_k, const Vec3& x_i, const Vec3& x_j,
                                               double min_range_m = 1e-6);

}  // namespace uwb
