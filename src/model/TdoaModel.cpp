/** @file TdoaModel.cpp
 *  @brief Range and TDoA model values and derivatives (paper eq. 1–3; docs/math/measurement.md M1–M5).
 */
#include "uwb/model/TdoaModel.h"

#include <cmath>
#include <stdexcept>

namespace uwb {

void TdoaModelParams::validate() const {
  if (!b_t_tag.allFinite()) throw std::invalid_argument("TdoaModelParams: b_t_tag must be finite");
  if (!(min_range_m > 0.0) || !std::isfinite(min_range_m)) {
    throw std::invalid_argument("TdoaModelParams: min_range_m must be finite and > 0");
  }
}

double range(const Vec3& p, const Vec3& a, RowVec3* J_range_p) {
  const Vec3 d = p - a;
  const double r = d.norm();
  if (J_range_p != nullptr) *J_range_p = d.transpose() / r;  // (M3), paper eq. (3): ∇‖d‖ = dᵀ/‖d‖
  return r;
}

double predictTdoa(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& b_t_tag, const Vec3& w_p_anchor_a,
                   const Vec3& w_p_anchor_b) {
  const Vec3 p = tagPosition(w_p_b, w_q_b, b_t_tag);
  return range(p, w_p_anchor_b) - range(p, w_p_anchor_a);  // (M1)
}

std::optional<double> evaluateTdoa(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& w_p_anchor_a,
                                   const Vec3& w_p_anchor_b, const TdoaModelParams& params, TdoaJacobians* J) {
  const Mat3 w_R_b = w_q_b.toRotationMatrix();
  const Vec3 w_p_tag = w_p_b + w_R_b * params.b_t_tag;  // (M2)
  const Vec3 d_a = w_p_tag - w_p_anchor_a;
  const Vec3 d_b = w_p_tag - w_p_anchor_b;
  const double r_a = d_a.norm();
  const double r_b = d_b.norm();
  if (!(r_a >= params.min_range_m) || !(r_b >= params.min_range_m)) return std::nullopt;  // tag on an anchor
  if (J != nullptr) {
    const RowVec3 u_a = d_a.transpose() / r_a;  // (M3)
    const RowVec3 u_b = d_b.transpose() / r_b;
    const RowVec3 J_z_tag = u_b - u_a;  // ∂z/∂p_tag
    J->J_z_p_b = J_z_tag;               // (M5): ∂p_tag/∂w_p_b = I
    J->J_z_dtheta = -(J_z_tag * w_R_b * skew(params.b_t_tag));  // (M4, M5): ∂p_tag/∂δθ = −R [b_t]×
    J->J_z_anchor_a = u_a;
    J->J_z_anchor_b = -u_b;
  }
  return r_b - r_a;  // (M1)
}

}  // namespace uwb
