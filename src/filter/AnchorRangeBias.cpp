#include "uwb/filter/AnchorRangeBias.h"

#include <cmath>
#include <stdexcept>

#include "uwb/graph/TdoaCorrection.h"

namespace uwb {

AnchorRangeBias::AnchorRangeBias(double sigma_m, double tau_s) : sigma_m_(sigma_m), tau_s_(tau_s) {
  if (!(sigma_m > 0.0) || !std::isfinite(sigma_m))
    throw std::invalid_argument("AnchorRangeBias: sigma_m must be finite and > 0");
  if (!(tau_s > 0.0) || !std::isfinite(tau_s))
    throw std::invalid_argument("AnchorRangeBias: tau_s must be finite and > 0");
  P_bb_ = BiasMat::Identity() * (sigma_m * sigma_m);
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
  return k < 0 ? sigma_m_ : std::sqrt(P_bb_(k, k));
}

void AnchorRangeBias::decay(double dt_s) {
  if (!(dt_s > 0.0)) return;
  // (F27b) exact discretisation of dβ = −β/τ dt + σ √(2/τ) dW
  const double f = std::exp(-dt_s / tau_s_);
  beta_ *= f;
  P_bx_ *= f;
  P_bb_ *= f * f;
  P_bb_.diagonal().array() += (1.0 - f * f) * sigma_m_ * sigma_m_;
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
