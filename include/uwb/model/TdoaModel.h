/** @file TdoaModel.h
 *  @brief TDoA measurement model with tag lever arm (paper eq. 1–2; docs/math/measurement.md eq. M1–M2).
 *
 *  UTIL sign convention: z = |p_tag − a_B| − |p_tag − a_A| + ε, p_tag = w_p_b + w_R_b · b_t_tag.
 */
#pragma once

#include "uwb/core/Types.h"

namespace uwb {

/// Range |p − a| (paper eq. 1); fills ∂/∂p when J_range_p is non-null. Undefined for p == a (caller checks).
double range(const Vec3& p, const Vec3& a, RowVec3* J_range_p = nullptr);

/// Tag position in the world frame: w_p_b + w_R_b b_t_tag.
inline Vec3 tagPosition(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& b_t_tag) {
  return w_p_b + w_q_b * b_t_tag;
}

/// Noise-free TDoA (paper eq. 2, UTIL convention): |p_tag − a_B| − |p_tag − a_A| [m].
double predictTdoa(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& b_t_tag, const Vec3& w_p_anchor_a,
                   const Vec3& w_p_anchor_b);

}  // namespace uwb
