/** @file BiasFloor.cpp
 *  @brief docs/math/filter.md F23: the position covariance of independent anchor range biases seen through pairs.
 */
#include "uwb/filter/BiasFloor.h"

#include <algorithm>

namespace uwb {
namespace {

/// Regularisation of the normal matrix: a degenerate geometry (all anchors in a line) gives a large, finite σ.
constexpr double kRegularisation = 1e-6;

template <typename M>
M sandwich(const M& A, const M& B, double s_a2) {
  const M A_inv = (A + kRegularisation * M::Identity()).inverse();
  return s_a2 * A_inv * B * A_inv;
}

}  // namespace

int BiasFloorGeometry::slot(int id, const Vec3& w_p_anchor) {
  for (int k = 0; k < n_anchors_; ++k)
    if (ids_[k] == id) return k;
  if (n_anchors_ == kMaxAnchors) return -1;
  const Vec3 d = w_p_tag_ - w_p_anchor;
  if (!(d.norm() > 1e-6)) return -1;
  const int n = n_anchors_;
  ids_[n] = id;
  unit_[n] = d.normalized();
  for (int k = 0; k <= n; ++k) laplacian_[n][k] = laplacian_[k][n] = 0.0;
  return n_anchors_++;
}

bool BiasFloorGeometry::addPair(int id_a, const Vec3& w_p_a, int id_b, const Vec3& w_p_b) {
  if (id_a == id_b) return false;
  const int ia = slot(id_a, w_p_a), ib = slot(id_b, w_p_b);
  if (ia < 0 || ib < 0) return false;
  if (laplacian_[ia][ib] != 0.0) return false;  // this pair, in either order, is already an edge
  laplacian_[ia][ia] += 1.0;
  laplacian_[ib][ib] += 1.0;
  laplacian_[ia][ib] -= 1.0;
  laplacian_[ib][ia] -= 1.0;
  ++n_pairs_;
  return true;
}

void BiasFloorGeometry::moments(Mat3* JtLJ, Mat3* JtL2J) const {
  // the pair rows are H = DJ (row u_B − u_A, M3), so HᵀH = JᵀLJ and HᵀDDᵀH = (LJ)ᵀ(LJ) with L = DᵀD
  JtLJ->setZero();
  JtL2J->setZero();
  for (int i = 0; i < n_anchors_; ++i) {
    Vec3 LJ_i = Vec3::Zero();
    for (int k = 0; k < n_anchors_; ++k) LJ_i += laplacian_[i][k] * unit_[k];
    *JtLJ += unit_[i] * LJ_i.transpose();
    *JtL2J += LJ_i * LJ_i.transpose();
  }
}

Mat3 BiasFloorGeometry::covariance(double sigma_pair_m) const {
  const double s2 = sigma_pair_m * sigma_pair_m;
  if (n_pairs_ < 3) return s2 * Mat3::Identity();
  Mat3 A, B;
  moments(&A, &B);
  // (F23) δp = (HᵀH)⁻¹HᵀDβ, β ~ N(0, σ_a² I), σ_a² = σ_pair²/2 (a pair's bias β_B − β_A has variance 2σ_a²)
  return sandwich<Mat3>(A, B, 0.5 * s2);
}

Eigen::Matrix2d BiasFloorGeometry::horizontalCovariance(double sigma_pair_m) const {
  const double s2 = sigma_pair_m * sigma_pair_m;
  if (n_pairs_ < 3) return s2 * Eigen::Matrix2d::Identity();
  Mat3 A, B;
  moments(&A, &B);
  // (F23′) with z known, H_xy = DJ_xy: the x, y blocks of the same moments
  return sandwich<Eigen::Matrix2d>(A.topLeftCorner<2, 2>(), B.topLeftCorner<2, 2>(), 0.5 * s2);
}

double BiasFloorGeometry::unexplainedTrace() const {
  if (n_pairs_ < 4) return 0.0;
  Mat3 A, B;
  moments(&A, &B);
  // tr(Q DDᵀ) with Q = I − H(HᵀH)⁻¹Hᵀ, H = DJ: tr(DDᵀ) = tr(DᵀD) = tr(L), tr(H(HᵀH)⁻¹HᵀDDᵀ) = tr((HᵀH)⁻¹HᵀDDᵀH)
  double trace_l = 0.0;
  for (int i = 0; i < n_anchors_; ++i) trace_l += laplacian_[i][i];
  const Mat3 A_inv = (A + kRegularisation * Mat3::Identity()).inverse();
  return std::max(trace_l - (A_inv * B).trace(), 0.0);
}

}  // namespace uwb
