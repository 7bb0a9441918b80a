/** @file GraphTestUtil.h
 *  @brief Brute-force Gaussian helpers for the graph tests: random SPD matrices, log densities, conditioning a
 *         dense joint Gaussian (the "ground truth" the node rules are compared with).
 */
#pragma once

#include <algorithm>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <random>

#include "uwb/graph/GaussianMessage.h"

namespace uwb::graphtest {

inline VecX randomVector(std::mt19937& rng, Eigen::Index n, double scale = 1.0) {
  std::normal_distribution<double> nd(0.0, scale);
  VecX v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = nd(rng);
  return v;
}

inline MatX randomMatrix(std::mt19937& rng, Eigen::Index r, Eigen::Index c) {
  std::normal_distribution<double> nd(0.0, 1.0);
  MatX M(r, c);
  for (Eigen::Index i = 0; i < r; ++i)
    for (Eigen::Index j = 0; j < c; ++j) M(i, j) = nd(rng);
  return M;
}

/// Random SPD matrix with eigenvalues roughly in [floor, floor + n].
inline MatX randomSpd(std::mt19937& rng, Eigen::Index n, double floor = 0.1) {
  const MatX A = randomMatrix(rng, n, n);
  return A * A.transpose() / static_cast<double>(n) + floor * MatX::Identity(n, n);
}

inline Moments randomMoments(std::mt19937& rng, Eigen::Index n) { return {randomVector(rng, n), randomSpd(rng, n)}; }

/// Unnormalized log density of a message in information form: −½ xᵀ W x + ξᵀ x.
inline double logInformation(const Information& msg, const VecX& x) { return -0.5 * x.dot(msg.W * x) + msg.xi.dot(x); }

/// Log density of N(m, V) up to the normalizing constant: −½ (x − m)ᵀ V⁻¹ (x − m).
inline double logMoments(const Moments& msg, const VecX& x) {
  const VecX d = x - msg.m;
  return -0.5 * d.dot(msg.V.llt().solve(d));
}

/// Conditional of the first block of a joint Gaussian N(m, V) (blocks sizes n1 + n2) given the second block = y.
inline Moments condition(const VecX& m, const MatX& V, Eigen::Index n1, const VecX& y) {
  const Eigen::Index n2 = m.size() - n1;
  const MatX V11 = V.topLeftCorner(n1, n1), V12 = V.topRightCorner(n1, n2), V22 = V.bottomRightCorner(n2, n2);
  const Eigen::FullPivLU<MatX> lu(V22);
  return {m.head(n1) + V12 * lu.solve(y - m.tail(n2)), V11 - V12 * lu.solve(V12.transpose())};
}

inline double maxAbs(const MatX& A) { return A.size() == 0 ? 0.0 : A.cwiseAbs().maxCoeff(); }

/// Largest absolute difference between two moment-form messages (Moments, Moments3, …), over means and covariances.
template <class MomentsA, class MomentsB>
double maxAbsDifference(const MomentsA& a, const MomentsB& b) {
  return std::max(maxAbs(a.m - b.m), maxAbs(a.V - b.V));
}

}  // namespace uwb::graphtest
