/** @file AnchorRangeBias.h
 *  @brief Per-anchor range bias as Ornstein–Uhlenbeck states of the filter, with their cross-covariance to the
 *         error state (docs/math/filter.md F27).
 *
 *  The TDoA error is a slowly varying, position-dependent bias of each anchor's range (multipath, occlusion, antenna
 *  delay), which a filter with white TDoA noise absorbs into its position. Here each anchor i in view carries a range
 *  bias β_i, a stationary Ornstein–Uhlenbeck process N(0, σ²) with correlation time τ, and the TDoA of pair (A, B)
 *  is z = |p − a_B| − |p − a_A| + β_B − β_A + e (F27a). The filter's error state is augmented by δβ = β − β̂; the
 *  blocks P_xβ and P_ββ of the joint covariance live here, P_xx in the Ekf. Anchors are given a slot the first time
 *  they are seen, up to kMaxBiasAnchors; an anchor without a slot has β = 0.
 */
#pragma once

#include <array>
#include <cmath>

#include <Eigen/Core>

#include "uwb/filter/StateIndex.h"

namespace uwb {

/// Largest number of anchors with a range-bias state (UTIL: 8; a Loco system: at most 16).
inline constexpr int kMaxBiasAnchors = 16;
/// The error state augmented by the anchor range biases: [δx (15), δβ (kMaxBiasAnchors)].
inline constexpr int kAugDim = kDim + kMaxBiasAnchors;
using AugVec = Eigen::Matrix<double, kAugDim, 1>;
using AugMat = Eigen::Matrix<double, kAugDim, kAugDim>;
using BiasVec = Eigen::Matrix<double, kMaxBiasAnchors, 1>;
using BiasMat = Eigen::Matrix<double, kMaxBiasAnchors, kMaxBiasAnchors>;
using CrossMat = Eigen::Matrix<double, kDim, kMaxBiasAnchors>;
/// P_βx = P_xβᵀ, stored by bias rows: the TDoA update reads its δp and δθ columns (contiguous).
using BiasRowsMat = Eigen::Matrix<double, kMaxBiasAnchors, kDim>;

class AnchorRangeBias {
 public:
  /// sigma_m: stationary std of each anchor's range bias [m] (> 0); tau_s: its correlation time [s] (> 0).
  /// Throws std::invalid_argument otherwise.
  AnchorRangeBias(double sigma_m, double tau_s);

  /// Slot of anchor `id`, given one if it has none and one is free; −1 when all are taken.
  int slot(int id);
  /// Slot of anchor `id`, −1 if it has none (no state is created).
  int findSlot(int id) const;
  /// β̂ of anchor `id` [m]; 0 for an anchor without a slot.
  double mean(int id) const;
  /// std of β of anchor `id` [m]; σ for an anchor without a slot (its prior).
  double stddev(int id) const;

  /// (F27b) The Ornstein–Uhlenbeck transition over dt_s ≥ 0 with f = e^{−dt/τ}: β̂ ← f β̂, P_ββ ← f² P_ββ + (1 − f²) σ² I,
  /// and the cross-covariance P_βx ← f P_βx (its δx side is the Ekf's business: P_βx ← P_βx Φᵀ).
  void decay(double dt_s);

  /// The joint covariance's cross and bias blocks times factor (a covariance intersection's P/ω, G21).
  void scale(double factor) {
    P_bx_ *= factor;
    P_bb_ *= factor;
  }
  /// Adds d_bx to P_βx and d_bb (symmetric) to P_ββ (the bias rows of a joint inflation, G21).
  void inflate(const BiasRowsMat& d_bx, const BiasMat& d_bb) {
    P_bx_ += d_bx;
    P_bb_ += d_bb;
  }

  /// The bias part of a rank-one correction of the joint covariance (G18): P_βx ← P_βx − w_β w_xᵀ,
  /// P_ββ ← P_ββ − w_β w_βᵀ, β̂ ← β̂ + dbeta (the Ekf downdates P by w_x w_xᵀ).
  void downdate(const ErrVec& w_x, const BiasVec& w_b, const BiasVec& dbeta);

  /// The joint covariance [[P, P_xβ], [P_xβᵀ, P_ββ]] for the Ekf's P (the plain reference of the block updates).
  AugMat joint(const ErrMat& P) const;

  const BiasVec& means() const { return beta_; }
  /// P_βx = Cov(δβ, δx) (kMaxBiasAnchors × 15).
  BiasRowsMat& biasRows() { return P_bx_; }
  const BiasRowsMat& biasRows() const { return P_bx_; }
  /// P_xβ = P_βxᵀ (15 × kMaxBiasAnchors).
  CrossMat cross() const { return P_bx_.transpose(); }
  const BiasMat& covariance() const { return P_bb_; }
  /// The constructor's stationary std σ₀ [m].
  double sigma() const { return sigma0_m_; }
  /// The stationary std in use [m]: σ₀, or the adapted one (F27e); also the prior of an anchor without a slot.
  double adaptedSigma() const { return std::sqrt(var_m2_); }
  /// (F27e) Adapts the anchors' common stationary std to the flight by online EM: σ² follows the posterior second
  /// moment β̂_k² + P_ββ,kk of the anchors corrected, averaged with time constant time_constant_s and bounded to
  /// [min_fraction² σ₀², σ₀²]. time_constant_s = 0 turns it off. Throws std::invalid_argument for time_constant_s < 0
  /// or min_fraction outside (0, 1].
  void enableAdaptation(double time_constant_s, double min_fraction);
  /// (F27e) One EM step after a correction that involved slots slot_a and slot_b (a slot < 0 is skipped); it weighs
  /// the time decay() was given since the last step.
  void adapt(int slot_a, int slot_b);
  double tau() const { return tau_s_; }

 private:
  double sigma0_m_;
  double tau_s_;
  double var_m2_;                  ///< σ² in use (σ₀² without adaptation, F27e)
  double adapt_s_ = 0.0;           ///< EM time constant [s]; 0 off
  double min_var_m2_ = 0.0;        ///< lower bound of the adapted σ²
  double second_moment_m2_ = 0.0;  ///< time average of β̂_k² + P_ββ,kk over the corrected anchors
  double t_since_adapt_s_ = 0.0;
  std::array<int, kMaxBiasAnchors> ids_{};
  int n_ = 0;
  BiasVec beta_ = BiasVec::Zero();
  BiasRowsMat P_bx_ = BiasRowsMat::Zero();
  BiasMat P_bb_;
};

}  // namespace uwb
