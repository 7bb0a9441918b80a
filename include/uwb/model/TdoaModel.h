/** @file TdoaModel.h
 *  @brief TDoA measurement model with tag lever arm and analytic Jacobians (paper eq. 1–2;
 *         docs/math/measurement.md M1–M6).
 *
 *  UTIL sign convention (data): z = |p_tag − a_B| − |p_tag − a_A| + ε,   p_tag = w_p_b + w_R_b · b_t_tag   (M1, M2).
 *  In the paper's notation z_ij = d_ki − d_kj (eq. 2) this is i = anchor B, j = anchor A.
 *
 *  Attitude error convention (shared with the filter): RIGHT perturbation, body-frame error,
 *      w_q_b(true) = w_q_b ⊗ exp(δθ),   w_R_b(true) = w_R_b · Exp(δθ),
 *  so ∂p_tag/∂δθ = −w_R_b [b_t_tag]×  (M4).
 */
#pragma once

#include <optional>

#include "uwb/core/Types.h"

namespace uwb {

/// Ranges shorter than this are treated as "tag on an anchor" (degenerate, the gradient is undefined) [m].
inline constexpr double kMinRange_m = 1e-9;

/// Skew-symmetric matrix [v]× with [v]× w = v × w.
inline Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

/// Range |p − a| (paper eq. 1; M3); fills ∂/∂p = (p − a)ᵀ/|p − a| when J_range_p is non-null.
/// Undefined for p == a (caller checks, or use evaluateTdoa which returns nullopt).
double range(const Vec3& p, const Vec3& a, RowVec3* J_range_p = nullptr);

/// Tag position in the world frame: w_p_b + w_R_b b_t_tag (M2).
inline Vec3 tagPosition(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& b_t_tag) {
  return w_p_b + w_q_b * b_t_tag;
}

/// Noise-free TDoA (paper eq. 2, UTIL convention): |p_tag − a_B| − |p_tag − a_A| [m]. No degeneracy check.
double predictTdoa(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& b_t_tag, const Vec3& w_p_anchor_a,
                   const Vec3& w_p_anchor_b);

/// Parameters of the TDoA measurement model.
struct TdoaModelParams {
  Vec3 b_t_tag = kUtilTagOffset_b;  ///< UWB antenna (tag) position in the body frame [m]
  double min_range_m = 1e-6;        ///< tag closer than this to an anchor → degenerate (nullopt) [m]
  /// Throws std::invalid_argument when a field is out of range (non-finite lever arm, min_range_m <= 0).
  void validate() const;
};

/// Analytic Jacobians of z = |p_tag − a_B| − |p_tag − a_A| (M5).
struct TdoaJacobians {
  RowVec3 J_z_p_b = RowVec3::Zero();       ///< ∂z/∂w_p_b (body origin, world frame) = u_Bᵀ − u_Aᵀ
  RowVec3 J_z_dtheta = RowVec3::Zero();    ///< ∂z/∂δθ (right, body-frame attitude error) = −(u_Bᵀ − u_Aᵀ) w_R_b [b_t]×
  RowVec3 J_z_anchor_a = RowVec3::Zero();  ///< ∂z/∂w_p_anchor_a = +u_Aᵀ
  RowVec3 J_z_anchor_b = RowVec3::Zero();  ///< ∂z/∂w_p_anchor_b = −u_Bᵀ
};

/// Predicted TDoA (UTIL convention, M1) and, when J is non-null, its Jacobians (M5).
/// Returns nullopt when the tag is within params.min_range_m of either anchor (degenerate geometry).
std::optional<double> evaluateTdoa(const Vec3& w_p_b, const Quat& w_q_b, const Vec3& w_p_anchor_a,
                                   const Vec3& w_p_anchor_b, const TdoaModelParams& params = {},
                                   TdoaJacobians* J = nullptr);

/// ∂p_tag/∂δθ for the right (body-frame) attitude error: −w_R_b [b_t_tag]× (M4). Useful for the filter's
/// C = ∂x_k/∂δx = [I, 0, −w_R_b [b_t]×, 0, 0].
inline Mat3 tagPositionJacobianAttitude(const Quat& w_q_b, const Vec3& b_t_tag) {
  return -(w_q_b.toRotationMatrix() * skew(b_t_tag));
}

}  // namespace uwb
