/** @file BiasFloor.h
 *  @brief The position covariance that a slowly varying TDoA bias causes (docs/math/filter.md F23): each anchor's
 *         range carries a bias of its own, and a pair (A, B) sees the difference of its two anchors' biases.
 *
 *  The filter treats the TDoA error as white; most of it is a bias that changes over metres (F12), which a long run of
 *  measurements cannot average away. Its effect on the least-squares position is what the reported covariance adds
 *  to the filter's own. Counting the bias per anchor, not per pair, makes the answer independent of how many pairs
 *  share an anchor: the eight neighbour pairs of TDoA2 and the up to 28 pairs of TDoA3 see the same eight anchors.
 */
#pragma once

#include <array>

#include "uwb/core/Types.h"

namespace uwb {

/// Geometry of the anchor pairs in view at one tag position, accumulated pair by pair without allocation.
class BiasFloorGeometry {
 public:
  static constexpr int kMaxAnchors = 32;

  explicit BiasFloorGeometry(const Vec3& w_p_tag) : w_p_tag_(w_p_tag) {}

  /// A pair (A, B) in view, anchors at w_p_a and w_p_b. A pair already added, in either order, is counted once; a
  /// pair whose anchor coincides with the tag, or beyond kMaxAnchors anchors, is skipped. Returns whether it counted.
  bool addPair(int id_a, const Vec3& w_p_a, int id_b, const Vec3& w_p_b);
  int numPairs() const { return n_pairs_; }
  int numAnchors() const { return n_anchors_; }

  /// (F23) Covariance of the least-squares position under independent anchor range biases whose differences have
  /// std sigma_pair_m per pair (σ_a² = σ_pair²/2): σ_a² (JᵀLJ)⁻¹ JᵀL²J (JᵀLJ)⁻¹, with J the unit vectors from the
  /// anchors to the tag and L the Laplacian of the pair graph. σ_pair² I with fewer than 3 pairs.
  Mat3 covariance(double sigma_pair_m) const;
  /// The same for the horizontal position with the height known (F23′): the x, y blocks of JᵀLJ and JᵀL²J.
  Eigen::Matrix2d horizontalCovariance(double sigma_pair_m) const;
  /// (F23c) E‖(I − H(HᵀH)⁻¹Hᵀ) Dβ‖² per unit σ_a²: the part of the pair biases that no position shift explains,
  /// tr(L) − tr((JᵀLJ)⁻¹ JᵀL²J) (= m − 3 for independent pair biases on a generic geometry). 0 with fewer than 4 pairs.
  double unexplainedTrace() const;

 private:
  int slot(int id, const Vec3& w_p_anchor);
  /// JᵀLJ (= HᵀH of the pair rows) and JᵀL²J (= HᵀDDᵀH).
  void moments(Mat3* JtLJ, Mat3* JtL2J) const;

  Vec3 w_p_tag_;
  int n_anchors_ = 0, n_pairs_ = 0;
  std::array<int, kMaxAnchors> ids_{};
  std::array<Vec3, kMaxAnchors> unit_{};                               ///< J's rows ∂d_i/∂p
  /// L = DᵀD; only the leading n_anchors_ × n_anchors_ block is initialised (slot() zeroes each new row and column:
  /// the whole array is 8 KB, and the geometry is rebuilt at the TDoA rate)
  std::array<std::array<double, kMaxAnchors>, kMaxAnchors> laplacian_;
};

}  // namespace uwb
