/** @file BiasCalibrationTest.cpp
 *  @brief Coverage and NLPD of predicted biases (docs/math/gp.md P43): calibrated, over- and under-confident.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "uwb/eval/BiasCalibration.h"

namespace uwb {
namespace {

std::vector<double> gaussianResiduals(std::size_t n, double sd, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sd);
  std::vector<double> r(n);
  for (auto& v : r) v = g(rng);
  return r;
}

TEST(BiasCalibration, IntervalHalfWidthsAreTheNormalQuantiles) {
  EXPECT_NEAR(centralIntervalHalfWidth(std::erf(1.0 / std::sqrt(2.0))), 1.0, 1e-12);
  EXPECT_NEAR(centralIntervalHalfWidth(0.95), 1.959963984540054, 1e-12);
  EXPECT_NEAR(centralIntervalHalfWidth(0.99), 2.5758293035489004, 1e-12);
  EXPECT_THROW(centralIntervalHalfWidth(1.0), std::invalid_argument);
  EXPECT_THROW(centralIntervalHalfWidth(0.0), std::invalid_argument);
}

TEST(BiasCalibration, CalibratedPredictionsCoverTheirNominalLevels) {
  // GIVEN residuals drawn from N(0, 0.2²) and the matching predicted variance
  const auto r = gaussianResiduals(40000, 0.2, 1);
  const std::vector<double> var(r.size(), 0.04);
  // WHEN scored
  const BiasCalibration c = biasCalibration(r, var);
  // THEN 1σ/2σ coverage is 68.3 / 95.4 %, every level is met and the NLPD is the Gaussian entropy
  EXPECT_NEAR(c.coverage_1sigma, 0.6827, 0.01);
  EXPECT_NEAR(c.coverage_2sigma, 0.9545, 0.005);
  ASSERT_EQ(c.coverage.size(), calibrationLevels().size());
  for (std::size_t k = 0; k < c.coverage.size(); ++k) EXPECT_NEAR(c.coverage[k], calibrationLevels()[k], 0.01);
  EXPECT_NEAR(c.nlpd, 0.5 * std::log(2 * kPi * 0.04) + 0.5, 0.01);
  EXPECT_NEAR(c.rmse_m, 0.2, 0.003);
  EXPECT_NEAR(c.mean_std_m, 0.2, 1e-12);
}

TEST(BiasCalibration, OverconfidentPredictionsUnderCoverAndPayInNlpd) {
  const auto r = gaussianResiduals(20000, 0.2, 2);
  const BiasCalibration good = biasCalibration(r, std::vector<double>(r.size(), 0.04));
  const BiasCalibration over = biasCalibration(r, std::vector<double>(r.size(), 0.0004));  // σ = 2 cm claimed
  const BiasCalibration under = biasCalibration(r, std::vector<double>(r.size(), 0.36));  // σ = 0.6 m claimed
  EXPECT_LT(over.coverage_1sigma, 0.1);
  EXPECT_GT(under.coverage_1sigma, 0.9);
  EXPECT_GT(over.nlpd, good.nlpd + 1.0);
  EXPECT_GT(under.nlpd, good.nlpd + 0.1);
}

TEST(BiasCalibration, RejectsBadInputAndWritesJson) {
  EXPECT_THROW(biasCalibration({0.1}, {0.0}), std::invalid_argument);
  EXPECT_THROW(biasCalibration({0.1, 0.2}, {0.1}), std::invalid_argument);
  const nlohmann::json j = toJson(biasCalibration({0.1, -0.3}, {0.04, 0.04}));
  EXPECT_EQ(j.at("n").get<int>(), 2);
  EXPECT_DOUBLE_EQ(j.at("coverage_1sigma").get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j.at("coverage_2sigma").get<double>(), 1.0);
  EXPECT_EQ(j.at("levels").size(), j.at("coverage").size());
}

TEST(BiasCalibration, ModelPredictiveAddsTheLikelihoodNoiseAndSkipsUncoveredPairs) {
  // GIVEN a per-pair yaw-angle model for pair (0, 1) only, with σ_n² = 0.03 and an extra filter variance
  gp::Svgp svgp(gp::Kernel::preset("z1"), MatX::Random(5, 2));
  svgp.setNoiseVariance(0.03);
  svgp.setMean(0.1);
  BiasModel model("z1", FeatureMap::kYawAngles, {{0, 1, svgp}});
  model.setExtraVariance(0.5);
  TdoaFeature f;
  f.id_a = 0;
  f.id_b = 1;
  f.yaw_a_rad = 0.3;
  f.yaw_b_rad = -1.2;
  // WHEN the predictive distribution of ε is asked for
  const BiasPredictive p = model.predictive(f);
  const gp::SvgpPrediction ref = svgp.predict((MatX(1, 2) << 0.3, -1.2).finished());
  // THEN it is the GP's latent mean and variance plus the likelihood noise, without the filter's extra variance
  EXPECT_TRUE(p.covered);
  EXPECT_NEAR(p.mean_m, ref.mean[0], 1e-12);
  EXPECT_NEAR(p.latent_variance_m2, ref.var_f[0], 1e-12);
  EXPECT_DOUBLE_EQ(p.noise_variance_m2, 0.03);
  EXPECT_NEAR(p.varianceM2(), ref.var_y[0], 1e-12);
  EXPECT_NEAR(model.predict(f).variance_m2, ref.var_f[0] + 0.5, 1e-12);
  // AND a pair without a model is left out of the calibration
  BiasDataset data;
  data.samples.push_back({f, 0.2, 0.0, 0});
  TdoaFeature g = f;
  g.id_a = 2;
  g.id_b = 3;
  data.samples.push_back({g, 0.2, 0.1, 0});
  EXPECT_FALSE(model.predictive(g).covered);
  const BiasCalibration c = biasCalibration(data, model);
  EXPECT_EQ(c.n, 1u);
  EXPECT_EQ(c.n_uncovered, 1u);
  EXPECT_NEAR(c.rmse_m, std::abs(0.2 - p.mean_m), 1e-12);
}

}  // namespace
}  // namespace uwb
