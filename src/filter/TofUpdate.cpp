/** @file TofUpdate.cpp
 *  @brief ToF height update: docs/math/filter.md F21 (Crazyflie kalmanCoreUpdateWithTof; Mueller et al. 2015).
 */
#include "uwb/filter/TofUpdate.h"

#include <cmath>

namespace uwb {

std::optional<double> tofPredictedRange(const NavState& x, double offset_m, double floor_z_m, ErrRow* J_h_dx) {
  // (F21) w_p_s = w_p_b + R b_t_s, b_t_s = −offset e3; the ray −R e3 meets z = floor_z after
  // (w_p_s,z − floor_z)/R33 = (p_z − floor_z)/R33 − offset.
  const Mat3 w_R_b = x.w_q_b.toRotationMatrix();
  const double R33 = w_R_b(2, 2);
  if (!(R33 > kTofMinCosTilt)) return std::nullopt;
  const double height_m = x.w_p_b.z() - floor_z_m;
  if (J_h_dx) {
    // R(q ⊗ exp(δθ)) ≈ R (I + [δθ]×) → ∂R33/∂δθ = (e3 × g)ᵀ = (−g_y, g_x, 0), g = Rᵀ e3 (world up in body).
    const Vec3 g = w_R_b.row(2).transpose();
    J_h_dx->setZero();
    (*J_h_dx)(kPos + 2) = 1.0 / R33;
    const double dh_dR33 = -height_m / (R33 * R33);
    (*J_h_dx)(kAtt + 0) = dh_dR33 * -g.y();
    (*J_h_dx)(kAtt + 1) = dh_dR33 * g.x();
  }
  return height_m / R33 - offset_m;
}

std::optional<double> tofMeasuredHeight(const Quat& w_q_b, double range_m, double offset_m) {
  const double R33 = w_q_b.toRotationMatrix()(2, 2);
  if (!(R33 > kTofMinCosTilt)) return std::nullopt;
  return (range_m + offset_m) * R33;
}

TofUpdateResult updateTof(Ekf& ekf, double range_m, const TofUpdateOptions& options) {
  TofUpdateResult res;
  if (!std::isfinite(range_m) || range_m <= 0.0 || range_m > options.max_range_m) return res;  // kSkipped
  ErrRow J;
  const std::optional<double> h = tofPredictedRange(ekf.state(), options.offset_m, options.floor_z_m, &J);
  if (!h) {
    res.outcome = UpdateOutcome::kDegenerate;
    return res;
  }
  ScalarLinearMessage<kDim> msg;
  msg.a = J;
  msg.y = range_m - *h;
  msg.var = options.sigma_m * options.sigma_m;
  const InnovationStats st = ekf.innovation(msg);
  res.innovation_m = st.innovation_m;
  res.nis = st.nis;
  if (options.gate_sigma > 0.0 && !OutlierGate(options.gate_sigma).accept(st.nis)) {
    res.outcome = UpdateOutcome::kRejectedOutlier;
    return res;
  }
  // the row is zero outside δp and δθ: the two-block equality node (G18) applies
  res.outcome = ekf.correctPositionAttitude(msg) ? UpdateOutcome::kApplied : UpdateOutcome::kDegenerate;
  return res;
}

}  // namespace uwb
