/** @file AntennaBias.cpp
 *  @brief The antenna-pattern TDoA bias learned online from the filter's innovations: docs/math/filter.md F25a–F25e.
 */
#include "uwb/filter/AntennaBias.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace uwb {

int antennaBasisSize(int max_degree) {
  if (max_degree < 2 || max_degree > kMaxAntennaDegree)
    throw std::invalid_argument("antenna basis: degree must be in [2, " + std::to_string(kMaxAntennaDegree) + "]");
  return (max_degree + 1) * (max_degree + 1) - 4;
}

AntennaVec antennaBasis(const Vec3& b_u, int max_degree) {
  // (F25a) Cartesian forms of the real orthonormal spherical harmonics on the unit sphere (the same convention as
  // the simulator's pattern, docs/math/simulation.md S13), degrees 2…4.
  const int n = antennaBasisSize(max_degree);
  const double x = b_u.x(), y = b_u.y(), z = b_u.z();
  const double x2 = x * x, y2 = y * y, z2 = z * z;
  AntennaVec phi(n);
  // l = 2
  phi(0) = 1.0925484305920792 * x * y;
  phi(1) = 1.0925484305920792 * y * z;
  phi(2) = 0.31539156525252005 * (3.0 * z2 - 1.0);
  phi(3) = 1.0925484305920792 * x * z;
  phi(4) = 0.5462742152960396 * (x2 - y2);
  if (max_degree >= 3) {
    phi(5) = 0.5900435899266435 * y * (3.0 * x2 - y2);
    phi(6) = 2.890611442640554 * x * y * z;
    phi(7) = 0.4570457994644658 * y * (5.0 * z2 - 1.0);
    phi(8) = 0.3731763325901154 * z * (5.0 * z2 - 3.0);
    phi(9) = 0.4570457994644658 * x * (5.0 * z2 - 1.0);
    phi(10) = 1.445305721320277 * z * (x2 - y2);
    phi(11) = 0.5900435899266435 * x * (x2 - 3.0 * y2);
  }
  if (max_degree >= 4) {
    phi(12) = 2.5033429417967046 * x * y * (x2 - y2);
    phi(13) = 1.7701307697799304 * y * z * (3.0 * x2 - y2);
    phi(14) = 0.9461746957575601 * x * y * (7.0 * z2 - 1.0);
    phi(15) = 0.6690465435572892 * y * z * (7.0 * z2 - 3.0);
    phi(16) = 0.10578554691520431 * (35.0 * z2 * z2 - 30.0 * z2 + 3.0);
    phi(17) = 0.6690465435572892 * x * z * (7.0 * z2 - 3.0);
    phi(18) = 0.47308734787878004 * (x2 - y2) * (7.0 * z2 - 1.0);
    phi(19) = 1.7701307697799304 * x * z * (x2 - 3.0 * y2);
    phi(20) = 0.6258357354491761 * (x2 * x2 - 6.0 * x2 * y2 + y2 * y2);
  }
  return phi;
}

void AntennaBiasParams::validate() const {
  antennaBasisSize(max_degree);
  if (!(std::isfinite(prior_sigma_m) && prior_sigma_m > 0.0))
    throw std::invalid_argument("AntennaBiasParams: prior_sigma_m must be finite and > 0");
  if (!(std::isfinite(memory_s) && memory_s >= 0.0))
    throw std::invalid_argument("AntennaBiasParams: memory_s must be finite and >= 0");
  if (!b_t_tag.allFinite()) throw std::invalid_argument("AntennaBiasParams: b_t_tag must be finite");
  if (!(std::isfinite(offset_sigma_m) && offset_sigma_m >= 0.0))
    throw std::invalid_argument("AntennaBiasParams: offset_sigma_m must be finite and >= 0");
  if (!(std::isfinite(offset_memory_s) && offset_memory_s > 0.0))
    throw std::invalid_argument("AntennaBiasParams: offset_memory_s must be finite and > 0");
}

OnlineAntennaBias::OnlineAntennaBias(const AntennaBiasParams& params) : params_(params), t_last_s_(0.0) {
  params_.validate();
  n_ = antennaBasisSize(params_.max_degree);
  x_ = AntennaStateVec::Zero(n_ + 3);
  P_ = AntennaStateMat::Zero(n_ + 3, n_ + 3);
  P_.diagonal().head(n_).setConstant(params_.prior_sigma_m * params_.prior_sigma_m);
  P_.diagonal().tail<3>().setConstant(params_.offset_sigma_m * params_.offset_sigma_m);
  row_last_ = AntennaStateVec::Zero(n_ + 3);
}

AntennaVec OnlineAntennaBias::regressor(const TdoaFeature& feature) const {
  // (F25b) directions seen from the antenna, not from the body origin (9 cm apart on the Crazyflie)
  const Vec3 b_d_a = feature.b_p_a - params_.b_t_tag;
  const Vec3 b_d_b = feature.b_p_b - params_.b_t_tag;
  const double n_a = b_d_a.norm(), n_b = b_d_b.norm();
  if (!(n_a > 1e-6 && n_b > 1e-6)) return AntennaVec::Zero(n_);
  return antennaBasis(b_d_b / n_b, params_.max_degree) - antennaBasis(b_d_a / n_a, params_.max_degree);
}

Vec3 OnlineAntennaBias::positionRow(const TdoaFeature& feature) {
  // (F25e) ∂z/∂p = (p − a_B)/|p − a_B| − (p − a_A)/|p − a_A| (M3), at the body origin
  const Vec3 d_a = feature.w_p_b - feature.w_p_anchor_a, d_b = feature.w_p_b - feature.w_p_anchor_b;
  const double n_a = d_a.norm(), n_b = d_b.norm();
  if (!(n_a > 1e-6 && n_b > 1e-6)) return Vec3::Zero();
  return d_b / n_b - d_a / n_a;
}

void OnlineAntennaBias::advance(double t_s) {
  if (!std::isfinite(t_s)) return;
  if (!has_time_) {
    has_time_ = true;
    t_last_s_ = t_s;
    return;
  }
  const double dt = t_s - t_last_s_;
  if (!(dt > 0.0)) return;  // an older stamp forgets nothing
  t_last_s_ = t_s;
  // (F25c) Ornstein–Uhlenbeck forgetting: each prior is its block's stationary distribution
  AntennaStateVec f = AntennaStateVec::Ones(n_ + 3);
  AntennaStateVec q = AntennaStateVec::Zero(n_ + 3);
  if (params_.memory_s > 0.0) {
    const double ft = std::exp(-dt / params_.memory_s);
    f.head(n_).setConstant(ft);
    q.head(n_).setConstant((1.0 - ft * ft) * params_.prior_sigma_m * params_.prior_sigma_m);
  }
  if (params_.offset_sigma_m > 0.0) {
    const double fo = std::exp(-dt / params_.offset_memory_s);
    f.tail<3>().setConstant(fo);
    q.tail<3>().setConstant((1.0 - fo * fo) * params_.offset_sigma_m * params_.offset_sigma_m);
  }
  x_ = x_.cwiseProduct(f);
  P_ = f.asDiagonal() * P_ * f.asDiagonal();
  P_.diagonal() += q;
}

BiasPrediction OnlineAntennaBias::predict(const TdoaFeature& feature) {
  row_last_.head(n_) = regressor(feature);
  row_last_.tail<3>() = params_.offset_sigma_m > 0.0 ? positionRow(feature) : Vec3::Zero();
  const auto h = row_last_.head(n_);
  BiasPrediction b;
  b.mean_m = h.dot(x_.head(n_));
  b.variance_m2 = h.dot(P_.topLeftCorner(n_, n_) * h);
  return b;
}

void OnlineAntennaBias::learn(double innovation_m, double innovation_var_m2) {
  if (!(std::isfinite(innovation_m) && std::isfinite(innovation_var_m2) && innovation_var_m2 > 0.0)) return;
  // (F25d) scalar Kalman update of (θ, ν); the offset ν is the part of the innovation that the filter's position
  // error explains (F25e), so θ learns only from what no position can explain
  const AntennaStateVec Pr = P_ * row_last_;
  const double s = innovation_var_m2 + row_last_.dot(Pr);
  // the innovation was formed with the mean of θ only; the offset's mean is predicted here
  const double r = innovation_m - row_last_.tail<3>().dot(x_.tail<3>());
  x_ += Pr * (r / s);
  P_.noalias() -= Pr * (Pr.transpose() / s);
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  ++n_learned_;
}

}  // namespace uwb
