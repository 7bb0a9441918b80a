/** @file BiasFloorTest.cpp
 *  @brief The position covariance of anchor range biases seen through pairs (docs/math/filter.md F23).
 */
#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "uwb/filter/BiasFloor.h"

namespace uwb {
namespace {

/// Eight anchors at the corners of a 4 × 4 × 2.5 m arena, low and high alternating around it as in the UTIL arenas.
std::vector<Vec3> arena() {
  return {Vec3(-2, -2, 0.2), Vec3(2, -2, 2.6), Vec3(2, 2, 0.2), Vec3(-2, 2, 2.6),
          Vec3(-2, -2, 2.6), Vec3(2, -2, 0.2), Vec3(2, 2, 2.6), Vec3(-2, 2, 0.2)};
}

/// TDoA2: each anchor paired with the next, a cycle of 8 pairs.
std::vector<std::pair<int, int>> cyclePairs() {
  std::vector<std::pair<int, int>> p;
  for (int i = 0; i < 8; ++i) p.push_back({i, (i + 1) % 8});
  return p;
}

/// TDoA3: every pair of anchors, 28 pairs.
std::vector<std::pair<int, int>> allPairs() {
  std::vector<std::pair<int, int>> p;
  for (int i = 0; i < 8; ++i)
    for (int j = i + 1; j < 8; ++j) p.push_back({i, j});
  return p;
}

BiasFloorGeometry geometry(const Vec3& tag, const std::vector<std::pair<int, int>>& pairs) {
  const std::vector<Vec3> a = arena();
  BiasFloorGeometry g(tag);
  for (const auto& [i, j] : pairs) g.addPair(i, a[i], j, a[j]);
  return g;
}

/// Sample covariance of the least-squares position shift (HᵀH)⁻¹Hᵀb when each anchor's range carries an independent
/// N(0, σ_a²) bias and pair (A, B) sees β_B − β_A: the definition F23 stands for, by simulation. With `dims` = 2 the
/// height is known and only x, y are solved for (F23′).
Eigen::MatrixXd monteCarlo(const Vec3& tag, const std::vector<std::pair<int, int>>& pairs, double sigma_a, int n,
                           int dims = 3) {
  const std::vector<Vec3> a = arena();
  Eigen::MatrixXd H(pairs.size(), dims);
  for (std::size_t k = 0; k < pairs.size(); ++k)
    H.row(k) = ((tag - a[pairs[k].second]).normalized() - (tag - a[pairs[k].first]).normalized()).head(dims);
  const Eigen::MatrixXd Hpinv = (H.transpose() * H).inverse() * H.transpose();
  std::mt19937 rng(3);
  std::normal_distribution<double> nd(0.0, sigma_a);
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(dims, dims);
  for (int s = 0; s < n; ++s) {
    Eigen::VectorXd beta(8), b(pairs.size());
    for (int i = 0; i < 8; ++i) beta(i) = nd(rng);
    for (std::size_t k = 0; k < pairs.size(); ++k) b(k) = beta(pairs[k].second) - beta(pairs[k].first);
    const Eigen::VectorXd dp = Hpinv * b;
    C += dp * dp.transpose();
  }
  return C / n;
}

TEST(BiasFloor, MatchesTheLeastSquaresShiftOfIndependentAnchorBiases) {
  // GIVEN a tag in the arena, the pairs of TDoA2 and of TDoA3, a pair std of 0.2 m (σ_a = 0.2/√2 per anchor)
  const Vec3 tag(0.4, -0.3, 1.5);
  const double sigma_pair = 0.2;
  for (const auto& pairs : {cyclePairs(), allPairs()}) {
    // WHEN the covariance is computed and the biases are simulated
    const Mat3 C = geometry(tag, pairs).covariance(sigma_pair);
    const Eigen::MatrixXd mc = monteCarlo(tag, pairs, sigma_pair / std::sqrt(2.0), 40000);
    // THEN they agree within the sampling error (≈ 1 % at 40 000 samples)
    EXPECT_LT((C - mc).norm(), 0.03 * C.norm()) << "pairs: " << pairs.size() << "\n" << C << "\n" << mc;
    // AND with the height known, the horizontal covariance agrees with the shift of x, y solved alone (F23′)
    const Eigen::Matrix2d Cxy = geometry(tag, pairs).horizontalCovariance(sigma_pair);
    const Eigen::MatrixXd mc_xy = monteCarlo(tag, pairs, sigma_pair / std::sqrt(2.0), 40000, 2);
    EXPECT_LT((Cxy - mc_xy).norm(), 0.03 * Cxy.norm()) << "pairs: " << pairs.size() << "\n" << Cxy << "\n" << mc_xy;
  }
}

TEST(BiasFloor, EachPairCountsOnceInEitherOrder) {
  // GIVEN the TDoA3 pairs, once as they are and once with every pair added again, reversed
  const Vec3 tag(-0.5, 0.7, 1.1);
  const BiasFloorGeometry once = geometry(tag, allPairs());
  std::vector<std::pair<int, int>> twice = allPairs();
  for (const auto& [i, j] : allPairs()) twice.push_back({j, i});
  const BiasFloorGeometry again = geometry(tag, twice);
  // THEN 28 pairs over 8 anchors are counted, and the covariance is the same
  EXPECT_EQ(once.numPairs(), 28);
  EXPECT_EQ(again.numPairs(), 28);
  EXPECT_EQ(again.numAnchors(), 8);
  EXPECT_LT((once.covariance(0.2) - again.covariance(0.2)).norm(), 1e-15);
}

TEST(BiasFloor, MorePairsOfTheSameAnchorsDoNotShrinkIt) {
  // GIVEN the same eight anchors seen through 8 pairs (TDoA2) and through 28 (TDoA3)
  const Vec3 tag(0.2, 0.1, 1.5);
  const Mat3 c8 = geometry(tag, cyclePairs()).covariance(0.2);
  const Mat3 c28 = geometry(tag, allPairs()).covariance(0.2);
  // THEN the 28 pairs, which carry no more independent biases, give a covariance of the same size (within 30 % per
  // axis), where counting a bias per pair would shrink it by about 28/8 · 1/2 (the complete graph's Laplacian has
  // twice the cycle's mean eigenvalue per pair)
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(c28(k, k), 0.7 * c8(k, k)) << "axis " << k;
    EXPECT_LT(c28(k, k), 1.3 * c8(k, k)) << "axis " << k;
  }
  // and on the complete graph L = nΠ, so the sandwich is exactly σ_a² n (JᵀLJ)⁻¹ = σ_a² (JᵀΠJ)⁻¹
  const std::vector<Vec3> a = arena();
  Eigen::Matrix<double, 8, 3> J;
  for (int i = 0; i < 8; ++i) J.row(i) = (tag - a[i]).normalized().transpose();
  const Eigen::Matrix<double, 8, 8> Pi =
      Eigen::Matrix<double, 8, 8>::Identity() - Eigen::Matrix<double, 8, 8>::Constant(1.0 / 8.0);
  const Mat3 expected = 0.5 * 0.04 * (J.transpose() * Pi * J).inverse();
  EXPECT_LT((c28 - expected).norm(), 1e-4 * expected.norm());
}

TEST(BiasFloor, FewPairsSayNothingAndBadPairsAreNotCounted) {
  const Vec3 tag(0.0, 0.0, 1.0);
  // GIVEN two pairs THEN the geometry says nothing and the covariance is σ² I
  const BiasFloorGeometry two = geometry(tag, {{0, 1}, {1, 2}});
  EXPECT_EQ(two.numPairs(), 2);
  EXPECT_LT((two.covariance(0.3) - 0.09 * Mat3::Identity()).norm(), 1e-15);
  EXPECT_LT((two.horizontalCovariance(0.3) - 0.09 * Eigen::Matrix2d::Identity()).norm(), 1e-15);
  // a pair of an anchor with itself, or at the tag, is not a pair
  BiasFloorGeometry h(tag);
  EXPECT_FALSE(h.addPair(3, arena()[3], 3, arena()[3]));
  EXPECT_FALSE(h.addPair(1, tag, 2, arena()[2]));
  EXPECT_EQ(h.numPairs(), 0);
}

TEST(BiasFloor, UnexplainedTraceIsTheExpectedResidualOfTheAnchorBiasesOffThePositionDirections) {
  // (F23c) E‖(I − H(HᵀH)⁻¹Hᵀ) Dβ‖² = σ_a² tr(Q DDᵀ): the dense projector, by definition, for the cycle and all pairs
  const std::vector<Vec3> a = arena();
  for (const auto& pairs : {cyclePairs(), allPairs()}) {
    const Vec3 tag(0.4, -0.7, 1.3);
    const int m = static_cast<int>(pairs.size());
    Eigen::MatrixXd H(m, 3), D = Eigen::MatrixXd::Zero(m, 8);
    for (int k = 0; k < m; ++k) {
      H.row(k) = ((tag - a[pairs[k].second]).normalized() - (tag - a[pairs[k].first]).normalized()).transpose();
      D(k, pairs[k].first) = -1.0;
      D(k, pairs[k].second) = 1.0;
    }
    const Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(m, m) - H * (H.transpose() * H).inverse() * H.transpose();
    const double expected = (Q * D * D.transpose()).trace();
    EXPECT_NEAR(geometry(tag, pairs).unexplainedTrace(), expected, 1e-6 * expected) << m << " pairs";
    // three position directions are taken out of the 2m of tr(DDᵀ), each at most DDᵀ's largest eigenvalue
    const double largest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(D * D.transpose()).eigenvalues().maxCoeff();
    EXPECT_LT(expected, 2.0 * m);
    EXPECT_GE(expected, 2.0 * m - 3.0 * largest - 1e-9);
  }
  EXPECT_EQ(geometry(Vec3(0, 0, 1), {{0, 1}, {1, 2}, {2, 3}}).unexplainedTrace(), 0.0);
}

}  // namespace
}  // namespace uwb
