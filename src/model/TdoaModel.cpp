/** @file TdoaModel.cpp
 *  @brief Range and TDoA model values and derivatives (paper eq. 1–3; docs/math/measurement.md M1–M3).
 */
#include "uwb/model/TdoaModel.h"

namespace uwb {

double range(const Vec3& p, const Vec3& a, RowVec3* J_range_p) {
  const Vec3 d = p - a;
  const double r = d.norm();
  if (J_range_p != nullptr) *J_range_p = d.transpose() / r;  // eq. (3): ∇‖d‖ = dᵀ/‖d‖
  return r;
}

double predictTdoa(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& b_t_tag, const Vec3& w_p_anchor_a,
                   const Vec3& w_p_anchor_b) {
  const Vec3 p = tagPosition(w_p_b, w_q_b, b_t_tag);
  return range(p, w_p_anchor_b) - range(p, w_p_anchor_a);
}

}  // namespace uwb
