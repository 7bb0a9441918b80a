/** @file BiasGuard.cpp
 *  @brief The corrected and the uncorrected filter mixed by their recent TDoA predictive likelihood
 *         (docs/math/filter.md F24).
 */
#include "uwb/filter/BiasGuard.h"

#include <algorithm>
#include <cmath>

namespace uwb {
namespace {

/// Huber scale of the predictive NLL on the normalised innovation (F24).
constexpr double kNllHuberK = 3.0;
/// The output weight moves at most this fast [1/s]: a full swing takes 2 s, so a switch between the two filters
/// (typically 0.1–0.3 m apart) moves the output by millimetres per 10 ms output (F24).
constexpr double kWeightSlew_per_s = 0.5;
/// Log-odds are bounded so that the weight can still turn within a few seconds when the evidence turns (F24).
constexpr double kMaxLogOdds = 30.0;

bool scored(const TdoaUpdateResult& r) {
  return (r.outcome == UpdateOutcome::kApplied || r.outcome == UpdateOutcome::kRejectedOutlier) &&
         r.innovation_var_m2 > 0.0;
}

}  // namespace

double predictiveNll(double nis, double innovation_var_m2) {
  if (!(innovation_var_m2 > 0.0)) return std::numeric_limits<double>::infinity();
  // (F24) Huber loss of u = √nis: ½u² inside k, k·u − ½k² outside
  const double u = std::sqrt(std::max(nis, 0.0));
  const double rho = u <= kNllHuberK ? 0.5 * u * u : kNllHuberK * u - 0.5 * kNllHuberK * kNllHuberK;
  return rho + 0.5 * std::log(innovation_var_m2);
}

GuardedEstimator::GuardedEstimator(const EkfParams& params, const AnchorTable& anchors, BiasPredictor bias)
    : corrected_(params, anchors, std::move(bias)), plain_(params, anchors), tau_s_(params.bias_guard_tau_s) {}

void GuardedEstimator::addImu(double t_s, const ImuReading& imu) {
  corrected_.addImu(t_s, imu);
  plain_.addImu(t_s, imu);
}

void GuardedEstimator::addTof(const TofObservation& tof) {
  corrected_.addTof(tof);
  plain_.addTof(tof);
}

void GuardedEstimator::addTdoa(const TdoaMeasurement& z) {
  corrected_.addTdoa(z);
  plain_.addTdoa(z);
  const TdoaUpdateResult& rc = corrected_.lastTdoaUpdate();
  const TdoaUpdateResult& ru = plain_.lastTdoaUpdate();
  // only TDoA that both filters predicted in flight enter the comparison (F24): on and near the floor the TDoA carry
  // the floor-level bias (F14), which neither filter models and no bias model was trained on
  if (!scored(rc) || !scored(ru) || !corrected_.lastTdoaInFlight() || !plain_.lastTdoaInFlight()) return;
  const double dt = std::isnan(t_last_) ? 0.0 : std::max(z.t_s - t_last_, 0.0);
  t_last_ = std::isnan(t_last_) ? z.t_s : std::max(t_last_, z.t_s);
  // (F24) L_k = e^{−Δt/τ} L_{k−1} + ℓ_u − ℓ_c, bounded; w follows σ(L) at a bounded rate
  log_odds_ = expNegative(dt / tau_s_) * log_odds_ + predictiveNll(ru.nis, ru.innovation_var_m2) -
              predictiveNll(rc.nis, rc.innovation_var_m2);
  log_odds_ = std::clamp(log_odds_, -kMaxLogOdds, kMaxLogOdds);
  const double target = 1.0 / (1.0 + std::exp(-log_odds_));
  const double max_step = kWeightSlew_per_s * dt;
  w_ += std::clamp(target - w_, -max_step, max_step);
  if (ready()) {
    w_time_sum_ += w_ * dt;
    time_sum_ += dt;
  }
}

LocalizerEstimate GuardedEstimator::estimate() const {
  LocalizerEstimate ec = corrected_.estimate();
  if (w_ >= 1.0) return ec;
  const LocalizerEstimate eu = plain_.estimate();
  if (w_ <= 0.0) return eu;
  // (F24) moment-matched mixture w·N(c) + (1 − w)·N(u): mean w m_c + (1 − w) m_u, covariance
  // w P_c + (1 − w) P_u + w (1 − w) d dᵀ with d = m_c − m_u; the attitude is interpolated on the sphere
  const double w = w_;
  const Vec3 dp = ec.x.w_p_b - eu.x.w_p_b;
  const Vec3 dv = ec.x.w_v_b - eu.x.w_v_b;
  LocalizerEstimate e = ec;
  e.x.w_p_b = eu.x.w_p_b + w * dp;
  e.x.w_v_b = eu.x.w_v_b + w * dv;
  e.x.w_q_b = eu.x.w_q_b.slerp(w, ec.x.w_q_b).normalized();
  e.x.b_acc_bias = w * ec.x.b_acc_bias + (1.0 - w) * eu.x.b_acc_bias;
  e.x.b_gyro_bias = w * ec.x.b_gyro_bias + (1.0 - w) * eu.x.b_gyro_bias;
  e.cov_pose = w * ec.cov_pose + (1.0 - w) * eu.cov_pose;
  e.cov_pose.block<3, 3>(0, 0) += w * (1.0 - w) * dp * dp.transpose();
  e.sigma_p_m = e.cov_pose.diagonal().head<3>().cwiseMax(0.0).cwiseSqrt();
  const Vec3 var_v = w * ec.sigma_v_mps.cwiseAbs2() + (1.0 - w) * eu.sigma_v_mps.cwiseAbs2() +
                     w * (1.0 - w) * dv.cwiseAbs2();
  e.sigma_v_mps = var_v.cwiseSqrt();
  return e;
}

LocalizerSummary GuardedEstimator::summary() const {
  LocalizerSummary s = corrected_.summary();
  s.bias_guard_mean_weight = time_sum_ > 0.0 ? w_time_sum_ / time_sum_ : w_;
  s.bias_guard_final_weight = w_;
  return s;
}

}  // namespace uwb
