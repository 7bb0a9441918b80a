/** @file CooperativeRange.cpp
 *  @brief Range to an uncertain neighbour (docs/math/message-passing.md G20), covariance intersection (G21),
 *         belief ageing (G22).
 */
#include "uwb/filter/CooperativeRange.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "uwb/model/TdoaModel.h"

namespace uwb {

std::optional<double> cooperativeRangePrediction(const NavState& x, const Vec3& b_t_tag, const Vec3& w_p_neighbour,
                                                 ErrRow* a, RowVec3* J_neighbour) {
  const Vec3 w_p_tag = tagPosition(x.w_p_b, x.w_q_b, b_t_tag);  // (M4)
  RowVec3 dh_dp;
  const double h = range(w_p_tag, w_p_neighbour, &dh_dp);  // (M3)
  if (!(h > 1e-3)) return std::nullopt;
  if (a) {
    // (G20) p_tag = p + R(q ⊗ exp δθ) b_t: ∂p_tag/∂δp = I, ∂p_tag/∂δθ = −R[b_t]× (M4)
    a->setZero();
    a->segment<3>(kPos) = dh_dp;
    a->segment<3>(kAtt) = dh_dp * tagPositionJacobianAttitude(x.w_q_b, b_t_tag);
  }
  if (J_neighbour) *J_neighbour = -dh_dp;
  return h;
}

double covarianceIntersectionWeight(double T, double u, double aPa, double q, double s_indep, double s_dep) {
  if (!(s_dep > 0.0)) return 1.0;
  // (G21) tr P⁺_pp(ω) = T/ω − u/(ω² S(ω)); golden-section search on (0, 1)
  const double a_not_p = std::max(aPa - q, 0.0);  // the part of aPaᵀ the inflation along the position leaves alone
  const auto trace = [&](double w) {
    const double S = a_not_p + q / w + s_indep + s_dep / (1.0 - w);
    return T / w - u / (w * w * S);
  };
  constexpr double kPhi = 0.6180339887498949;
  double lo = 1e-3, hi = 1.0 - 1e-6;
  double x1 = hi - kPhi * (hi - lo), x2 = lo + kPhi * (hi - lo);
  double f1 = trace(x1), f2 = trace(x2);
  for (int it = 0; it < 60; ++it) {
    if (f1 < f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - kPhi * (hi - lo);
      f1 = trace(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + kPhi * (hi - lo);
      f2 = trace(x2);
    }
  }
  return 0.5 * (lo + hi);
}

CooperativeRangeResult updateCooperativeRange(Ekf& ekf, const Moments3& neighbour, double range_m,
                                              const CooperativeRangeOptions& options) {
  CooperativeRangeResult res;
  if (!std::isfinite(range_m)) return res;  // kSkipped
  ErrRow a;
  RowVec3 J_j;
  const std::optional<double> h = cooperativeRangePrediction(ekf.state(), options.b_t_tag, neighbour.m, &a, &J_j);
  if (!h) {
    res.outcome = UpdateOutcome::kDegenerate;
    return res;
  }
  const double s_indep = options.sigma_m * options.sigma_m;
  const double s_dep = (J_j * neighbour.V * J_j.transpose())(0, 0);  // (G20) the neighbour as an uncertain anchor
  double omega = 1.0;
  const ErrMat& P = ekf.covariance();
  const ErrVec Pa = P * a.transpose();
  const double aPa = (a * Pa)(0, 0);
  double q = aPa;  // (G21) the part of aPaᵀ through the position
  if (options.fusion == NeighbourFusion::kCovarianceIntersection) {
    const Eigen::LLT<Mat3> llt(P.block<3, 3>(kPos, kPos));
    if (llt.info() == Eigen::Success) q = Pa.segment<3>(kPos).dot(llt.solve(Pa.segment<3>(kPos)));
    omega = covarianceIntersectionWeight(P.block<3, 3>(kPos, kPos).trace(), Pa.segment<3>(kPos).squaredNorm(), aPa,
                                         q, s_indep, s_dep);
  }
  ScalarLinearMessage<kDim> msg;
  msg.a = a;
  msg.y = range_m - *h;
  // (G21) naive: s = σ² + J_j Σ_j J_jᵀ; CI: the prior inflated along the position (P_pp/ω) with
  // s = σ² + J_j Σ_j J_jᵀ/(1 − ω)
  msg.var = omega < 1.0 ? s_indep + s_dep / (1.0 - omega) : s_indep + s_dep;
  if (!(msg.var > 0.0)) msg.var = 1e-12;
  const double S = std::max(aPa - q, 0.0) + q / omega + msg.var;
  res.innovation_m = msg.y;
  res.nis = msg.y * msg.y / S;
  res.omega = omega;
  if (options.gate_sigma > 0.0 && !OutlierGate(options.gate_sigma).accept(res.nis)) {
    res.outcome = UpdateOutcome::kRejectedOutlier;
    return res;
  }
  // (G21) inflated along the position; where P_pp is not positive definite, the whole covariance (plain CI)
  if (omega < 1.0 && !ekf.inflateAlongPosition(1.0 / omega)) ekf.scaleCovariance(1.0 / omega);
  res.outcome = ekf.correctPositionAttitude(msg) ? UpdateOutcome::kApplied : UpdateOutcome::kDegenerate;
  return res;
}

Moments3 tagBelief(const NavState& x, const Eigen::Matrix<double, 6, 6>& cov_pose, const Vec3& b_t_tag) {
  Eigen::Matrix<double, 3, 6> C;
  C.leftCols<3>().setIdentity();
  C.rightCols<3>() = tagPositionJacobianAttitude(x.w_q_b, b_t_tag);  // (M4)
  Moments3 out;
  out.m = tagPosition(x.w_p_b, x.w_q_b, b_t_tag);
  out.V = C * cov_pose * C.transpose();
  out.V = 0.5 * (out.V + out.V.transpose()).eval();
  return out;
}

Moments3 ageBelief(const Moments3& belief, const Vec3& w_v, const Mat3& cov_v, double age_s, double a_max_mps2) {
  // (G22) constant velocity over the age, an unmodelled acceleration up to a_max as extra isotropic variance
  const double dt = std::abs(age_s);
  const double drift = 0.5 * a_max_mps2 * dt * dt;
  Moments3 out;
  out.m = belief.m + w_v * age_s;
  out.V = belief.V + (dt * dt) * cov_v + (drift * drift) * Mat3::Identity();
  return out;
}

}  // namespace uwb
