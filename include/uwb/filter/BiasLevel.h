/** @file BiasLevel.h
 *  @brief The size of the slowly varying TDoA bias of the flight at hand, measured in flight from the residuals that
 *         no position explains (docs/math/filter.md F23c), for the reported covariance of F23.
 *
 *  F23 maps a per-anchor range bias of a fixed std into the reported position covariance. Flights differ: the
 *  bias of one is twice that of another (obstacles, the path through the anchors' patterns), and a fixed std is then
 *  too wide on one and too narrow on the other. What a position shift cannot absorb shows in the residuals: over a
 *  short window the pair residuals' means, projected off the three position directions, estimate the anchors' bias
 *  variance (a variance-component estimate). The estimate is forgotten exponentially, so it follows the flight and
 *  is never fixed for good.
 */
#pragma once

#include <array>

#include "uwb/core/Types.h"

namespace uwb {

class BiasLevel {
 public:
  static constexpr int kMaxPairs = 64;
  static constexpr double kWindow_s = 0.5;     ///< the window over which a pair's residuals are averaged
  static constexpr int kMinSamplesPerPair = 3;  ///< samples of a pair in a window for its mean to count
  static constexpr int kMinPairs = 5;           ///< pairs in a window (m − 3 ≥ 2 unexplained directions)
  static constexpr double kPriorWindows = 10.0; ///< the prior level counts as this many windows

  /// memory_s: time constant of the exponential forgetting of the windows' statistics (> 0).
  explicit BiasLevel(double memory_s);

  /// One TDoA residual z − ẑ of pair (A, B) without the filter's own range-bias states, at the tag position
  /// w_p_tag. A residual later than the window's end closes the window first.
  void add(double t_s, int id_a, const Vec3& w_p_a, int id_b, const Vec3& w_p_b, const Vec3& w_p_tag,
           double residual_m);
  /// Drops the open window without counting it (the residuals stop being those of the flight: a landing, a
  /// re-acquisition). The statistics of closed windows are kept.
  void interrupt();

  /// (F23c) The anchors' bias variance σ̂_a² of the windows so far, shrunk towards prior_sigma_a2 by kPriorWindows
  /// windows of the mean weight; prior_sigma_a2 before the first window.
  double sigmaA2(double prior_sigma_a2) const;
  /// The pair-bias level √(2σ̂_a²) (2σ_a² is a pair's bias variance, F23), shrunk towards prior_level_m as sigmaA2
  /// is towards prior_level_m² / 2.
  double pairLevel(double prior_level_m) const;
  /// The windows' pair-bias level alone, without a prior; NaN before the first window.
  double pairLevelData() const;
  /// Windows counted so far (not forgotten).
  int numWindows() const { return n_windows_; }

 private:
  struct PairSum {
    int id_a = 0, id_b = 0;
    Vec3 w_p_a = Vec3::Zero(), w_p_b = Vec3::Zero();
    int n = 0;
    double sum = 0.0, sum_sq = 0.0;
  };
  void closeWindow(double t_s);

  double memory_s_;
  std::array<PairSum, kMaxPairs> pairs_{};
  int n_pairs_ = 0;
  double t_window_s_ = 0.0;
  bool window_open_ = false;
  Vec3 tag_sum_ = Vec3::Zero();
  int n_samples_ = 0;
  // exponentially forgotten sums of the windows' unexplained residual R_w, weight τ_w and count
  double sum_r_ = 0.0, sum_tau_ = 0.0, sum_n_ = 0.0;
  double t_last_close_s_ = 0.0;
  int n_windows_ = 0;
};

/// (gp.md P43c) The TDoA error variance a flight shows beyond a bias model's training flights and beyond what the
/// model's mean explains: max(0, (ℓ² − ℓ_µ²) − (ℓ_train² − ℓ_µ,train²)) of the pair levels (F23c; ℓ_µ the level of
/// the mean, F24c). The ℓ_µ terms drop unless both are known; 0 unless ℓ and ℓ_train are known (known: finite, > 0).
double levelExcessVariance(double level_m, double mean_level_m, double train_level_m, double train_mean_level_m);

}  // namespace uwb
