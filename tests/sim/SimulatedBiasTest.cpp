/** @file SimulatedBiasTest.cpp
 *  @brief The range-bias field: orthonormal harmonics, dependence on body-frame direction only, NLOS sign.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "uwb/sim/SimulatedBias.h"
#include "uwb/sim/Scenario.h"

namespace uwb::sim {
namespace {

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

TEST(SphericalHarmonics, AreOrthonormalOnTheSphere) {
  // GIVEN many uniform directions (Monte Carlo estimate of ∫ Y_i Y_j dΩ = 4π E[Y_i Y_j])
  std::mt19937_64 rng(1);
  Eigen::Matrix<double, 16, 16> G = Eigen::Matrix<double, 16, 16>::Zero();
  const int n = 200000;
  for (int k = 0; k < n; ++k) {
    const auto Y = realSphericalHarmonics(randomUnit(rng));
    const Eigen::Map<const Eigen::Matrix<double, 16, 1>> y(Y.data());
    G += y * y.transpose();
  }
  G *= 4.0 * kPi / n;
  // THEN the Gram matrix is the identity (to Monte Carlo accuracy)
  EXPECT_LT((G - Eigen::Matrix<double, 16, 16>::Identity()).cwiseAbs().maxCoeff(), 0.03);
}

/// The defaults without the anchors' pattern and offsets, with the tag's antenna pattern and its NLOS shadow as asked.
BiasParams tagPatternTerms(bool antenna, bool nlos) {
  BiasParams p;
  p.anchor_pattern_rms_m = 0.0;
  p.anchor_offset_std_m = 0.0;
  if (!antenna) p.antenna_rms_m = 0.0;
  if (!nlos) p.nlos_bias_m = 0.0;
  return p;
}

TEST(SimulatedBias, PatternRmsMatchesTheParameter) {
  // GIVEN a model with only the tag antenna pattern
  const BiasParams p = tagPatternTerms(/*antenna=*/true, /*nlos=*/false);
  std::mt19937_64 rng(3);
  const SimulatedBias model(p, paperAnchors(), rng);
  // WHEN we average its square over the sphere
  double sq = 0.0;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    const double b = model.patternBias(0, randomUnit(rng));
    sq += b * b;
  }
  // THEN its RMS is antenna_rms_m
  EXPECT_NEAR(std::sqrt(sq / n), p.antenna_rms_m, 0.03 * p.antenna_rms_m);
}

TEST(SimulatedBias, PatternDependsOnlyOnTheBodyFrameDirection) {
  // GIVEN a model and two poses from which anchor 3 is seen along the same body-frame direction
  BiasParams p;
  p.multipath_std_m = 0.0;
  p.noise_std_m = 0.0;
  p.outlier_probability = 0.0;
  p.burst_probability = 0.0;
  p.ground_effect = false;
  std::mt19937_64 rng(5);
  const AnchorSurvey survey = paperAnchors();
  const SimulatedBias model(p, survey, rng);
  const Vec3 a3 = survey.position(3);
  const Vec3 a4 = survey.position(4);
  const Quat q1(Eigen::AngleAxisd(0.4, Vec3::UnitZ()));
  const Vec3 p1(0.5, -0.3, 1.4);
  // second pose: rotate the whole geometry about anchor 3 by a yaw; the direction to anchor 3 in the body frame
  // is unchanged, anchor 4 moves in the body frame
  const Quat turn(Eigen::AngleAxisd(0.9, Vec3::UnitZ()));
  const Quat q2 = turn * q1;
  const Vec3 p2 = a3 + turn * (p1 - a3);
  const Vec3 u1 = (q1.conjugate() * (a3 - p1)).normalized();
  const Vec3 u2 = (q2.conjugate() * (a3 - p2)).normalized();
  ASSERT_LT((u1 - u2).norm(), 1e-12);
  // THEN anchor 3's range bias is the same, anchor 4's is not
  EXPECT_NEAR(model.patternBias(3, u1), model.patternBias(3, u2), 1e-12);
  const Vec3 v1 = (q1.conjugate() * (a4 - p1)).normalized();
  const Vec3 v2 = (q2.conjugate() * (a4 - p2)).normalized();
  EXPECT_GT(std::abs(model.patternBias(4, v1) - model.patternBias(4, v2)), 1e-4);
  // AND the TDoA error is β_B − β_A (S17)
  std::mt19937_64 noise(1);
  const TdoaErrorParts e = model.sample(1.0, 3, 4, p1, q1, 1.4, noise);
  EXPECT_NEAR(e.total(), model.patternBias(4, v1) - model.patternBias(3, u1), 1e-6);  // tag lever arm excluded
}

TEST(SimulatedBias, BodyOcclusionAddsPositiveBiasBelowTheRotorPlane) {
  // GIVEN a model whose only term is the NLOS shadow
  const BiasParams p = tagPatternTerms(/*antenna=*/false, /*nlos=*/true);
  std::mt19937_64 rng(7);
  const SimulatedBias model(p, paperAnchors(), rng);
  // THEN directions above the plane get no bias, far below get the full positive bias (more toward the battery)
  EXPECT_EQ(model.patternBias(0, Vec3(1, 0, 0.5).normalized()), 0.0);
  const double below_front = model.patternBias(0, Vec3(1, 0, -1).normalized());
  const double below_back = model.patternBias(0, Vec3(-1, 0, -1).normalized());
  EXPECT_NEAR(below_front, p.nlos_bias_m * (1.0 - p.nlos_azimuth_gain), 1e-12);
  EXPECT_NEAR(below_back, p.nlos_bias_m * (1.0 + p.nlos_azimuth_gain), 1e-12);
}

TEST(SimulatedBias, MultipathFieldHasTheConfiguredSpreadAndLength) {
  BiasParams p;
  std::mt19937_64 rng(9);
  const SimulatedBias model(p, paperAnchors(), rng);
  std::mt19937_64 pts(2);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  double sq = 0.0, near_corr = 0.0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const Vec3 x(u(pts), u(pts), 1.5 + 0.3 * u(pts));
    const double m0 = model.multipathBias(1, x);
    sq += m0 * m0;
    near_corr += m0 * model.multipathBias(1, x + Vec3(0.05, 0.0, 0.0));
  }
  // about σ (random features: a ±30 % draw), and strongly correlated 5 cm away
  EXPECT_NEAR(std::sqrt(sq / n), p.multipath_std_m, 0.3 * p.multipath_std_m);
  EXPECT_GT(near_corr / sq, 0.9);
}

TEST(SimulatedBias, SharedFieldGeneratorGivesTheSameHardwareAndRoomButOwnGroundOffsets) {
  // GIVEN two models whose hardware/room terms come from equally seeded generators, flight terms from different ones
  const BiasParams p;
  std::mt19937_64 field_a(5), field_b(5), flight_a(1), flight_b(2);
  const SimulatedBias a(p, paperAnchors(), field_a, flight_a);
  const SimulatedBias b(p, paperAnchors(), field_b, flight_b);
  // THEN patterns, offsets and multipath agree everywhere, ground offsets (a per-flight draw) do not
  std::mt19937_64 dirs(3);
  for (int k = 0; k < 50; ++k) {
    const Vec3 u = randomUnit(dirs);
    const Vec3 x = 2.0 * randomUnit(dirs);
    for (const Anchor& anchor : paperAnchors().anchors) {
      EXPECT_EQ(a.patternBias(anchor.id, u), b.patternBias(anchor.id, u));
      EXPECT_EQ(a.multipathBias(anchor.id, x), b.multipathBias(anchor.id, x));
    }
  }
  int same_ground = 0;
  for (const Anchor& anchor : paperAnchors().anchors) same_ground += a.groundBias(anchor.id) == b.groundBias(anchor.id);
  EXPECT_EQ(same_ground, 0);
  // AND one generator for both reproduces the one-generator constructor exactly
  std::mt19937_64 one(7), two(7);
  const SimulatedBias c(p, paperAnchors(), one);
  const SimulatedBias d(p, paperAnchors(), two, two);
  const Vec3 u = randomUnit(dirs);
  EXPECT_EQ(c.patternBias(1, u), d.patternBias(1, u));
  EXPECT_EQ(c.groundBias(2), d.groundBias(2));
}

TEST(SimulatedBias, RejectsInvalidParameters) {
  BiasParams p;
  p.antenna_degree = 5;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = BiasParams{};
  p.noise_std_m = -0.1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = BiasParams{};
  p.ground_low_min_m = 4.0;
  p.ground_low_max_m = 3.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace uwb::sim
