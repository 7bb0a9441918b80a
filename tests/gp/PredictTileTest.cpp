/** @file PredictTileTest.cpp
 *  @brief The fused mean / kᵀQ_u k tile of the batch predictor (docs/math/gp.md P33): the plain reference (compiled
 *         in every build) and the version the build uses (AVX2 with UWB_NATIVE=ON) against the direct formulas
 *         mean_i = Σ_j k_ij α_j and var_i = k_iᵀ Q k_i, for panel-boundary sizes of M.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "uwb/gp/PredictTile.h"

namespace uwb::gp {
namespace {

TEST(PredictTile, ReferenceAndBuildVersionMatchTheDirectFormulas) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  for (Eigen::Index M : {1, 2, 5, 6, 7, 12, 13, 64, 171}) {
    SCOPED_TRACE("M = " + std::to_string(M) + (tileMeanQuadFormIsVectorized() ? " (AVX2 build)" : " (portable build)"));
    // GIVEN a column-major kernel block of one tile (leading dimension 16: a tile inside a larger block),
    // a symmetric Q and α
    const Eigen::Index ld = 16;
    AlignedDoubles buf(static_cast<std::size_t>(ld * M));
    Eigen::Map<MatX> K(buf.data(), ld, M);
    for (Eigen::Index i = 0; i < K.size(); ++i) K.data()[i] = n(rng);
    MatX Q(M, M);
    for (Eigen::Index i = 0; i < Q.size(); ++i) Q.data()[i] = n(rng);
    Q = (Q + Q.transpose()).eval();
    VecX alpha(M);
    for (Eigen::Index i = 0; i < M; ++i) alpha[i] = n(rng);
    const std::vector<double> qpack = packQuPanels(Q);
    // WHEN the tile of rows 8…15 is evaluated by both versions
    double mean_ref[kTilePoints], var_ref[kTilePoints], mean[kTilePoints], var[kTilePoints];
    tileMeanQuadFormReference(buf.data() + 8, ld, M, qpack.data(), alpha.data(), mean_ref, var_ref);
    tileMeanQuadForm(buf.data() + 8, ld, M, qpack.data(), alpha.data(), mean, var);
    // THEN both equal the direct formulas, and each other
    for (int i = 0; i < kTilePoints; ++i) {
      const VecX k = K.row(8 + i).transpose();
      const double mean_direct = k.dot(alpha), var_direct = k.dot(Q * k);
      const double scale_m = k.cwiseAbs().dot(alpha.cwiseAbs()), scale_v = k.cwiseAbs().dot(Q.cwiseAbs() * k.cwiseAbs());
      EXPECT_NEAR(mean_ref[i], mean_direct, 1e-13 * scale_m) << "point " << i;
      EXPECT_NEAR(var_ref[i], var_direct, 1e-13 * scale_v) << "point " << i;
      EXPECT_NEAR(mean[i], mean_ref[i], 1e-14 * scale_m) << "point " << i;
      EXPECT_NEAR(var[i], var_ref[i], 1e-14 * scale_v) << "point " << i;
    }
    // AND without a variance output only the mean is written
    double mean_only[kTilePoints];
    tileMeanQuadForm(buf.data() + 8, ld, M, qpack.data(), alpha.data(), mean_only, nullptr);
    for (int i = 0; i < kTilePoints; ++i) EXPECT_EQ(mean_only[i], mean[i]);
  }
}

TEST(PredictTile, PackedPanelsHoldTheDoubledUpperTriangle) {
  // GIVEN a 7×7 symmetric Q (two panels of 6 columns: the second has one real column)
  MatX Q(7, 7);
  for (Eigen::Index i = 0; i < 7; ++i)
    for (Eigen::Index j = 0; j < 7; ++j) Q(i, j) = 10.0 * static_cast<double>(std::min(i, j)) + static_cast<double>(std::max(i, j));
  const std::vector<double> q = packQuPanels(Q);
  // THEN panel 0 has rows 0…5 of columns 0…5, panel 1 rows 0…6 of column 6 (and five zero columns)
  ASSERT_EQ(q.size(), static_cast<std::size_t>(6 * 6 + 7 * 6));
  EXPECT_EQ(q[0 * 6 + 0], Q(0, 0));        // diagonal kept
  EXPECT_EQ(q[0 * 6 + 1], 2.0 * Q(0, 1));  // off-diagonal doubled
  EXPECT_EQ(q[1 * 6 + 0], 0.0);            // below the diagonal
  EXPECT_EQ(q[36 + 6 * 6 + 0], Q(6, 6));   // panel 1, row 6, column 6
  EXPECT_EQ(q[36 + 2 * 6 + 0], 2.0 * Q(2, 6));
  EXPECT_EQ(q[36 + 2 * 6 + 1], 0.0);       // past column M − 1
}

TEST(PredictTile, AlignedBufferStartsOnACacheLine) {
  for (std::size_t n : {1u, 7u, 1000u}) {
    AlignedDoubles b(n);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b.data()) % 64, 0u);
  }
}

}  // namespace
}  // namespace uwb::gp
