/** @file BiasLevel.cpp
 *  @brief docs/math/filter.md F23c: the anchors' bias variance from the pair residuals that no position explains.
 */
#include "uwb/filter/BiasLevel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "uwb/filter/BiasFloor.h"

namespace uwb {

BiasLevel::BiasLevel(double memory_s) : memory_s_(memory_s) {
  if (!(memory_s > 0.0) || !std::isfinite(memory_s))
    throw std::invalid_argument("BiasLevel: memory_s must be finite and > 0");
}

void BiasLevel::add(double t_s, int id_a, const Vec3& w_p_a, int id_b, const Vec3& w_p_b, const Vec3& w_p_tag,
                    double residual_m) {
  if (!std::isfinite(residual_m) || id_a == id_b) return;
  if (window_open_ && !(t_s - t_window_s_ < kWindow_s && t_s >= t_window_s_)) closeWindow(t_s);
  if (!window_open_) {
    window_open_ = true;
    t_window_s_ = t_s;
  }
  // a pair counts once in either order: (B, A) sees the negative of (A, B)
  const bool swapped = id_a > id_b;
  const double r = swapped ? -residual_m : residual_m;
  const Vec3& a = swapped ? w_p_b : w_p_a;
  const Vec3& b = swapped ? w_p_a : w_p_b;
  if (swapped) std::swap(id_a, id_b);
  PairSum* p = nullptr;
  for (int k = 0; k < n_pairs_ && !p; ++k)
    if (pairs_[k].id_a == id_a && pairs_[k].id_b == id_b) p = &pairs_[k];
  if (!p) {
    if (n_pairs_ == kMaxPairs) return;
    p = &pairs_[n_pairs_++];
    *p = PairSum{id_a, id_b, a, b, 0, 0.0, 0.0};
  }
  ++p->n;
  p->sum += r;
  p->sum_sq += r * r;
  tag_sum_ += w_p_tag;
  ++n_samples_;
}

void BiasLevel::interrupt() {
  window_open_ = false;
  n_pairs_ = 0;
  n_samples_ = 0;
  tag_sum_.setZero();
}

void BiasLevel::closeWindow(double t_s) {
  // (F23c) per pair k its window mean r̄_k, with rows h_k = u_B − u_A at the window's mean tag position:
  //   R = r̄ᵀ(I − H(HᵀH)⁻¹Hᵀ) r̄ − Σ_k (s_k²/n_k)(1 − h_kᵀ(HᵀH)⁻¹h_k),   E[R] = σ_a² τ,  τ = tr(L) − tr((JᵀLJ)⁻¹JᵀL²J)
  // (the second term removes the white noise left in the means; s_k² is the pair's sample variance in the window)
  const Vec3 w_p_tag = tag_sum_ / std::max(n_samples_, 1);
  BiasFloorGeometry geometry(w_p_tag);
  std::array<Vec3, kMaxPairs> h;
  std::array<double, kMaxPairs> mean, noise;
  std::array<bool, kMaxPairs> used{};
  Mat3 A = Mat3::Zero();
  Vec3 g = Vec3::Zero();
  double rr = 0.0;
  int m = 0;
  for (int k = 0; k < n_pairs_; ++k) {
    const PairSum& p = pairs_[k];
    if (p.n < kMinSamplesPerPair) continue;
    const Vec3 da = w_p_tag - p.w_p_a, db = w_p_tag - p.w_p_b;
    if (!(da.norm() > 1e-6 && db.norm() > 1e-6)) continue;
    if (!geometry.addPair(p.id_a, p.w_p_a, p.id_b, p.w_p_b)) continue;
    h[k] = db.normalized() - da.normalized();  // ∂(‖p − b‖ − ‖p − a‖)/∂p (M3)
    mean[k] = p.sum / p.n;
    noise[k] = std::max(p.sum_sq - p.n * mean[k] * mean[k], 0.0) / (p.n - 1) / p.n;
    used[k] = true;
    A += h[k] * h[k].transpose();
    g += h[k] * mean[k];
    rr += mean[k] * mean[k];
    ++m;
  }
  interrupt();
  const double tau = geometry.unexplainedTrace();
  if (m < kMinPairs || !(tau > 0.0)) return;
  const Eigen::LDLT<Mat3> ldlt(A);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-9)) return;
  double r_w = rr - g.dot(ldlt.solve(g));
  for (int k = 0; k < kMaxPairs; ++k)
    if (used[k]) r_w -= noise[k] * (1.0 - h[k].dot(ldlt.solve(h[k])));
  // not clamped per window: a window of noise alone reads below zero as often as above (clamped, it would bias a
  // small level up); the estimate itself is clamped
  const double f = n_windows_ == 0 ? 0.0 : std::exp(-std::max(t_s - t_last_close_s_, 0.0) / memory_s_);
  sum_r_ = f * sum_r_ + r_w;
  sum_tau_ = f * sum_tau_ + tau;
  sum_n_ = f * sum_n_ + 1.0;
  t_last_close_s_ = t_s;
  ++n_windows_;
}

double BiasLevel::sigmaA2(double prior_sigma_a2) const {
  if (n_windows_ == 0) return prior_sigma_a2;
  // the prior counts as kPriorWindows windows of the mean weight τ̄ = Σ τ_w / Σ 1
  const double c = kPriorWindows * sum_tau_ / sum_n_;
  return std::max((sum_r_ + c * prior_sigma_a2) / (sum_tau_ + c), 0.0);
}

double BiasLevel::pairLevel(double prior_level_m) const {
  return std::sqrt(2.0 * sigmaA2(0.5 * prior_level_m * prior_level_m));
}

double BiasLevel::pairLevelData() const {
  if (n_windows_ == 0 || !(sum_tau_ > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(2.0 * std::max(sum_r_ / sum_tau_, 0.0));
}

double levelExcessVariance(double level_m, double mean_level_m, double train_level_m, double train_mean_level_m) {
  const auto known = [](double l) { return std::isfinite(l) && l > 0.0; };
  if (!known(level_m) || !known(train_level_m)) return 0.0;
  // (P43c) what no mean explains, on this flight against the training flights
  double unexplained = level_m * level_m, trained = train_level_m * train_level_m;
  if (known(mean_level_m) && known(train_mean_level_m)) {
    unexplained -= mean_level_m * mean_level_m;
    trained -= train_mean_level_m * train_mean_level_m;
  }
  return std::max(0.0, unexplained - trained);
}

}  // namespace uwb
