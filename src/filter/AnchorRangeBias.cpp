#include "uwb/filter/AnchorRangeBias.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "uwb/graph/TdoaCorrection.h"

namespace uwb {

AnchorRangeBias::AnchorRangeBias(double sigma_m, double tau_s)
    : sigma0_m_(sigma_m), tau_s_(tau_s), var_m2_(sigma_m * sigma_m) {
  if (!(sigma_m > 0.0) || !std::isfinite(sigma_m))
    throw std::invalid_argument("AnchorRangeBias: sigma_m must be finite and > 0");
  if (!(tau_s > 0.0) || !std::isfinite(tau_s))
    throw std::invalid_argument("AnchorRangeBias: tau_s must be finite and > 0");
  P_bb_ = BiasMat::Identity() * (sigma_m * sigma_m);
  second_moment_m2_ = var_m2_;
}

void AnchorRangeBias::enableAdaptation(double time_constant_s, double min_fraction) {
  if (!(time_constant_s >= 0.0) || !std::isfinite(time_constant_s))
    throw std::invalid_argument("AnchorRangeBias: the adaptation time constant must be finite and >= 0");
  if (!(min_fraction > 0.0 && min_fraction <= 1.0))
    throw std::invalid_argument("AnchorRangeBias: the adaptation's min_fraction must be in (0, 1]");
  adapt_s_ = time_constant_s;
  min_var_m2_ = min_fraction * min_fraction * sigma0_m_ * sigma0_m_;
}

void AnchorRangeBias::adapt(int slot_a, int slot_b) {
  if (!(adapt_s_ > 0.0)) return;
  // (F27e) online EM for σ²: under the model E[β̂_k² + P_kk] = σ² (total variance); the posterior second moment of the
  // anchors just corrected is one sample of the M-step's σ², averaged over adapt_s_ of flight
  double m = 0.0;
  int n = 0;
  for (const int k : {slot_a, slot_b}) {
    if (k < 0) continue;
    m += beta_(k) * beta_(k) + P_bb_(k, k);
    ++n;
  }
  if (n == 0) return;
  const double alpha = -std::expm1(-t_since_adapt_s_ / adapt_s_);
  t_since_adapt_s_ = 0.0;
  second_moment_m2_ += alpha * (m / n - second_moment_m2_);
  var_m2_ = std::clamp(second_moment_m2_, min_var_m2_, sigma0_m_ * sigma0_m_);
}

int AnchorRangeBias::findSlot(int id) const {
  for (int k = 0; k < n_; ++k)
    if (ids_[k] == id) return k;
  return -1;
}

int AnchorRangeBias::slot(int id) {
  const int k = findSlot(id);
  if (k >= 0 || n_ == kMaxBiasAnchors) return k;
  // a fresh slot holds the prior N(0, σ²), uncorrelated with δx and the other anchors (constructor, decay)
  ids_[n_] = id;
  return n_++;
}

double AnchorRangeBias::mean(int id) const {
  const int k = findSlot(id);
  return k < 0 ? 0.0 : beta_(k);
}

double AnchorRangeBias::stddev(int id) const {
  const int k = findSlot(id);
  return k < 0 ? std::sqrt(var_m2_) : std::sqrt(P_bb_(k, k));
}

void AnchorRangeBias::decay(double dt_s) {
  if (!(dt_s > 0.0)) return;
  t_since_adapt_s_ += dt_s;
  // (F27b) exact discretisation of dβ = −β/τ dt + σ √(2/τ) dW
  const double f = std::exp(-dt_s / tau_s_);
  beta_ *= f;
  P_bx_ *= f;
  P_bb_ *= f * f;
  P_bb_.diagonal().array() += (1.0 - f * f) * var_m2_;
}

void AnchorRangeBias::downdate(const ErrVec& w_x, const BiasVec& w_b, const BiasVec& dbeta) {
  P_bx_.noalias() -= w_b * w_x.transpose();
  detail::rankOneDowndate<kMaxBiasAnchors>(P_bb_, w_b);
  beta_ += dbeta;
}

AugMat AnchorRangeBias::joint(const ErrMat& P) const {
  AugMat J;
  J.topLeftCorner<kDim, kDim>() = P;
  J.topRightCorner<kDim, kMaxBiasAnchors>() = P_bx_.transpose();
  J.bottomLeftCorner<kMaxBiasAnchors, kDim>() = P_bx_;
  J.bottomRightCorner<kMaxBiasAnchors, kMaxBiasAnchors>() = P_bb_;
  return J;
}

}  // namespace uwb
