/** @file BiasLevelTest.cpp
 *  @brief The flight's bias level from the residuals that no position explains (docs/math/filter.md F23c).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "uwb/filter/BiasLevel.h"

namespace uwb {
namespace {

/// Eight anchors at the corners of a 4 × 4 × 2.5 m arena, low and high alternating, and the TDoA2 cycle of pairs.
std::vector<Vec3> arena() {
  return {Vec3(-2, -2, 0.2), Vec3(2, -2, 2.6), Vec3(2, 2, 0.2), Vec3(-2, 2, 2.6),
          Vec3(-2, -2, 2.6), Vec3(2, -2, 0.2), Vec3(2, 2, 2.6), Vec3(-2, 2, 0.2)};
}

struct SyntheticFlight {
  double sigma_a_m = 0.15;    ///< each anchor's range bias, redrawn per window
  double shift_m = 0.0;       ///< a position error per window, which the residuals carry through h·δp
  double noise_m = 0.1;       ///< white noise per TDoA
  int samples_per_pair = 10;  ///< TDoA of each pair per 0.5 s window
  bool reversed = false;      ///< every other pair reported as (B, A)
};

/// Feeds `windows` windows of residuals z − ẑ = β_B − β_A + h·δp + e at a tag circling the arena's centre.
void feed(BiasLevel* level, const SyntheticFlight& f, int windows, double t0_s, std::mt19937* rng) {
  const std::vector<Vec3> a = arena();
  std::normal_distribution<double> nd(0.0, 1.0);
  for (int w = 0; w < windows; ++w) {
    std::vector<double> beta(8);
    for (double& b : beta) b = f.sigma_a_m * nd(*rng);
    const Vec3 shift = f.shift_m * Vec3(nd(*rng), nd(*rng), nd(*rng));
    for (int s = 0; s < 8 * f.samples_per_pair; ++s) {
      const double t = t0_s + BiasLevel::kWindow_s * (w + (s + 0.5) / (8.0 * f.samples_per_pair));
      const Vec3 tag(1.0 * std::cos(0.3 * t), 1.0 * std::sin(0.3 * t), 1.2);
      const int i = s % 8, j = (s + 1) % 8;
      const Vec3 h = (tag - a[j]).normalized() - (tag - a[i]).normalized();
      const double r = beta[j] - beta[i] + h.dot(shift) + f.noise_m * nd(*rng);
      if (f.reversed && i % 2 == 1) level->add(t, j, a[j], i, a[i], tag, -r);
      else level->add(t, i, a[i], j, a[j], tag, r);
    }
  }
}

TEST(BiasLevel, RecoversTheAnchorsBiasLevelWhateverThePositionError) {
  // the residuals' means projected off the position directions estimate σ_a²; a position error of 0.5 m per window
  // (larger than the bias) must not enter, and the white noise left in the means is removed
  for (const double shift : {0.0, 0.5}) {
    BiasLevel level(1000.0);
    std::mt19937 rng(11);
    SyntheticFlight f;
    f.shift_m = shift;
    feed(&level, f, 400, 0.0, &rng);
    EXPECT_GE(level.numWindows(), 399);
    EXPECT_NEAR(std::sqrt(level.sigmaA2(f.sigma_a_m * f.sigma_a_m)), f.sigma_a_m, 0.08 * f.sigma_a_m) << shift;
    // a prior far off counts as kPriorWindows of the 400 windows
    const double shrunk = std::sqrt((400.0 * f.sigma_a_m * f.sigma_a_m + BiasLevel::kPriorWindows * 0.25) /
                                    (400.0 + BiasLevel::kPriorWindows));
    EXPECT_NEAR(std::sqrt(level.sigmaA2(0.5 * 0.5)), shrunk, 0.08 * shrunk) << shift;
  }
}

TEST(BiasLevel, WhiteNoiseAloneIsNotABias) {
  BiasLevel level(1000.0);
  std::mt19937 rng(12);
  SyntheticFlight f;
  f.sigma_a_m = 0.0;
  f.noise_m = 0.3;
  f.samples_per_pair = 5;
  feed(&level, f, 400, 0.0, &rng);
  // without the noise term the window means would read σ_a ≈ 0.3/√5/√2 ≈ 0.095 m; the prior's share is 10 of ~400
  // windows of a tiny prior
  EXPECT_LT(std::sqrt(level.sigmaA2(1e-6)), 0.03);
}

TEST(BiasLevel, APairCountsTheSameInEitherOrder) {
  BiasLevel forward(1000.0), reversed(1000.0);
  std::mt19937 rng_f(13), rng_r(13);
  SyntheticFlight f;
  feed(&forward, f, 50, 0.0, &rng_f);
  f.reversed = true;  // (B, A) with the negated residual: the same data
  feed(&reversed, f, 50, 0.0, &rng_r);
  EXPECT_NEAR(forward.sigmaA2(0.01), reversed.sigmaA2(0.01), 1e-12);
}

TEST(BiasLevel, FollowsAChangeOfLevelAndStartsFromThePrior) {
  BiasLevel level(10.0);
  EXPECT_EQ(level.sigmaA2(0.04), 0.04);  // no window yet: the prior
  std::mt19937 rng(14);
  SyntheticFlight f;
  f.sigma_a_m = 0.05;
  feed(&level, f, 120, 0.0, &rng);  // 60 s of a small bias
  // a memory of 10 s holds n = 1/(1 − e^(−0.5/10)) ≈ 20.5 windows, and the prior counts as kPriorWindows more
  const double n = 1.0 / (1.0 - std::exp(-BiasLevel::kWindow_s / 10.0)), k = BiasLevel::kPriorWindows;
  const double prior = 0.15 * 0.15;
  EXPECT_NEAR(std::sqrt(level.sigmaA2(prior)), std::sqrt((n * 0.05 * 0.05 + k * prior) / (n + k)), 0.015);
  f.sigma_a_m = 0.3;
  feed(&level, f, 120, 60.0, &rng);  // 60 s = 6 memories of a large one
  EXPECT_NEAR(std::sqrt(level.sigmaA2(prior)), std::sqrt((n * 0.3 * 0.3 + k * prior) / (n + k)), 0.04);
}

TEST(BiasLevel, AnInterruptedWindowIsNotCountedAndSparseWindowsSayNothing) {
  BiasLevel level(30.0);
  std::mt19937 rng(15);
  SyntheticFlight f;
  f.sigma_a_m = 1.0;
  feed(&level, f, 1, 0.0, &rng);  // one full window, still open
  level.interrupt();
  EXPECT_EQ(level.numWindows(), 0);
  EXPECT_EQ(level.sigmaA2(0.01), 0.01);
  // two samples per pair are too few for a window mean
  f.samples_per_pair = 2;
  feed(&level, f, 20, 10.0, &rng);
  EXPECT_EQ(level.numWindows(), 0);
  EXPECT_THROW(BiasLevel(0.0), std::invalid_argument);
  EXPECT_THROW(BiasLevel(std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
