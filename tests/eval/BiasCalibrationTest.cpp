/** @file BiasCalibrationTest.cpp
 *  @brief Coverage and NLPD of predicted biases (docs/math/gp.md P43): calibrated, over- and under-confident; the
 *         Student-t predictive shape (P43b).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "uwb/eval/BiasCalibration.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/eval/BiasDataset.h"
#include "uwb/filter/BiasLevel.h"
#include "uwb/filter/EkfParams.h"

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

/// ∫ exp(log p(r)) dr over [a, b] by composite Simpson with n (even) intervals.
double integrateDensity(double a, double b, double var, const PredictiveShape& shape, int n = 20000) {
  const double h = (b - a) / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += w * std::exp(predictiveLogDensity(a + i * h, var, shape));
  }
  return sum * h / 3.0;
}

TEST(PredictiveShape, TheIntervalHalfWidthHoldsItsProbabilityUnderTheDensity) {
  // GIVEN the Gaussian and Student-t shapes, with and without a scale, and σ = 0.2 m
  const double var = 0.04, sd = 0.2;
  for (const PredictiveShape shape : {PredictiveShape::gaussian(), PredictiveShape{0.0, 0.8}, PredictiveShape{3.0, 1.0},
                                      PredictiveShape{5.0, 0.9}, PredictiveShape{12.5, 1.3}}) {
    SCOPED_TRACE(::testing::Message() << "dof " << shape.dof << " scale " << shape.scale);
    // THEN the density integrates to one, and the central interval of each level holds that probability
    EXPECT_NEAR(integrateDensity(-400.0 * sd, 400.0 * sd, var, shape, 400000), 1.0, 2e-3);
    for (const double p : {0.2, kOneSigmaMass, 0.9, kTwoSigmaMass, 0.99}) {
      const double w = centralIntervalHalfWidth(p, shape);
      EXPECT_NEAR(integrateDensity(-w * sd, w * sd, var, shape), p, 1e-9) << "p " << p;
    }
  }
  // AND known quantiles: t₅ at 0.975 (2.5705818366), the Gaussian's ±1σ and ±2σ masses
  EXPECT_NEAR(centralIntervalHalfWidth(0.95, PredictiveShape{5.0, 1.0}), 2.5705818366147395, 1e-9);
  EXPECT_NEAR(centralIntervalHalfWidth(kOneSigmaMass, PredictiveShape::gaussian()), 1.0, 1e-12);
  EXPECT_NEAR(centralIntervalHalfWidth(kTwoSigmaMass, PredictiveShape::gaussian()), 2.0, 1e-12);
  // AND a t with many degrees of freedom is the Gaussian
  EXPECT_NEAR(centralIntervalHalfWidth(0.9, PredictiveShape{1e7, 1.0}), centralIntervalHalfWidth(0.9), 1e-6);
  EXPECT_NEAR(predictiveLogDensity(0.3, var, PredictiveShape{1e7, 1.0}),
              predictiveLogDensity(0.3, var, PredictiveShape::gaussian()), 1e-6);
}

TEST(PredictiveShape, InvalidShapesAreRejectedNamingTheField) {
  for (const PredictiveShape bad : {PredictiveShape{1.5, 1.0}, PredictiveShape{-1.0, 1.0}, PredictiveShape{5.0, 0.0},
                                    PredictiveShape{5.0, std::nan("")}, PredictiveShape{std::nan(""), 1.0}}) {
    try {
      bad.validate();
      ADD_FAILURE() << "accepted dof " << bad.dof << " scale " << bad.scale;
    } catch (const std::invalid_argument& e) {
      EXPECT_TRUE(std::string(e.what()).find("predictive_") != std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(centralIntervalHalfWidth(1.0, PredictiveShape{}), std::invalid_argument);
  EXPECT_THROW(biasCalibration({0.1}, {0.04}, PredictiveShape{2.0, 1.0}), std::invalid_argument);
}

TEST(PredictiveShape, HeavyTailedResidualsAreCoveredByTheMatchingShapeAndNotByTheGaussian) {
  // GIVEN residuals r = 0.15 m · T₅ (std::student_t_distribution, independent of the implementation), whose
  // variance is σ² = 0.15² · 5/3
  std::mt19937_64 rng(7);
  std::student_t_distribution<double> t5(5.0);
  const double s = 0.15, var = s * s * 5.0 / 3.0;
  std::vector<double> r(200000);
  for (auto& v : r) v = s * t5(rng);
  const std::vector<double> variance(r.size(), var);
  // WHEN scored with the t₅ shape of scale s/σ and with the Gaussian of the same variance
  const BiasCalibration matched = biasCalibration(r, variance, PredictiveShape{5.0, s / std::sqrt(var)});
  const BiasCalibration gauss = biasCalibration(r, variance);
  // THEN the matching shape covers each level as claimed, and its NLPD is lower
  EXPECT_NEAR(matched.coverage_1sigma, kOneSigmaMass, 0.005);
  EXPECT_NEAR(matched.coverage_2sigma, kTwoSigmaMass, 0.003);
  const std::vector<double>& levels = calibrationLevels();
  for (std::size_t k = 0; k < levels.size(); ++k) EXPECT_NEAR(matched.coverage[k], levels[k], 0.006) << levels[k];
  EXPECT_LT(matched.nlpd, gauss.nlpd - 0.01);
  // AND the Gaussian of the same variance is over-wide at 1σ and too narrow at the 2σ mass (the heavy-tail signature)
  EXPECT_GT(gauss.coverage_1sigma, kOneSigmaMass + 0.03);
  EXPECT_LT(gauss.coverage_2sigma, kTwoSigmaMass - 0.003);
  EXPECT_EQ(matched.shape.dof, 5.0);
  const nlohmann::json j = toJson(matched);
  EXPECT_EQ(j.at("predictive_dof").get<double>(), 5.0);
}

TEST(PredictiveShape, TheModelFileCarriesTheShapeAndAnOlderFileGetsTheDefault) {
  gp::Svgp svgp(gp::Kernel::preset("z1"), MatX::Random(5, 2));
  BiasModel model("z1", FeatureMap::kYawAngles, {{0, 1, svgp}});
  EXPECT_EQ(model.predictiveShape().dof, PredictiveShape{}.dof);
  model.setPredictiveShape({7.0, 1.1});
  nlohmann::json j = model.toJson();
  const BiasModel back = BiasModel::fromJson(j);
  EXPECT_EQ(back.predictiveShape().dof, 7.0);
  EXPECT_EQ(back.predictiveShape().scale, 1.1);
  j.erase("predictive_dof");
  j.erase("predictive_scale");
  EXPECT_EQ(BiasModel::fromJson(j).predictiveShape().dof, PredictiveShape{}.dof);
  EXPECT_EQ(BiasModel::fromJson(j).predictiveShape().scale, PredictiveShape{}.scale);
  j["predictive_dof"] = 1.0;
  try {
    BiasModel::fromJson(j);
    ADD_FAILURE() << "dof 1 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(std::string(e.what()).find("predictive_dof") != std::string::npos) << e.what();
  }
}

TEST(BiasModelLevel, TheModelFileCarriesTheTrainingLevelsAndTheFilterGetsThemUnlessGiven) {
  // (filter.md F24b, F24c) the training flights' bias level and the level of the model's own mean on them travel with
  // the model to the filter's parameters, each alike
  struct Level {
    const char* field;
    double (BiasModel::*get)() const;
    void (BiasModel::*set)(double);
    double EkfParams::*param;
  };
  const Level levels[] = {
      {"training_bias_level_m", &BiasModel::trainingBiasLevel, &BiasModel::setTrainingBiasLevel,
       &EkfParams::bias_model_training_level_m},
      {"training_mean_level_m", &BiasModel::trainingMeanLevel, &BiasModel::setTrainingMeanLevel,
       &EkfParams::bias_model_training_mean_level_m}};
  for (const Level& l : levels) {
    SCOPED_TRACE(l.field);
    gp::Svgp svgp(gp::Kernel::preset("z1"), MatX::Random(5, 2));
    BiasModel model("z1", FeatureMap::kYawAngles, {{0, 1, svgp}});
    EXPECT_EQ((model.*l.get)(), 0.0);  // unknown
    (model.*l.set)(0.31);
    nlohmann::json j = model.toJson();
    EXPECT_EQ((BiasModel::fromJson(j).*l.get)(), 0.31);
    EkfParams p;
    applyBiasModelLevel(BiasModel::fromJson(j), &p);
    EXPECT_EQ(p.*l.param, 0.31);
    p.*l.param = 0.2;  // given by the user: kept
    applyBiasModelLevel(BiasModel::fromJson(j), &p);
    EXPECT_EQ(p.*l.param, 0.2);
    j.erase(l.field);  // an older file: unknown, nothing scaled or compared
    EXPECT_EQ((BiasModel::fromJson(j).*l.get)(), 0.0);
    EXPECT_THROW((model.*l.set)(std::nan("")), std::invalid_argument);
    EXPECT_THROW((model.*l.set)(-0.1), std::invalid_argument);
    EXPECT_THROW((model.*l.set)(11.0), std::invalid_argument);
  }
}

TEST(BiasModelLevel, TheMeanLevelIsTheWindowStatisticOfTheModelsMeanAndScalesWithIt) {
  // GIVEN eight anchors around a body that hovers in two flights, one sample of each neighbour pair every 10 ms for
  // 20 s, and models that predict a constant mean per pair (no GP: the pair means of P28), c and 2c
  const std::vector<Vec3> anchors = {{-4, -4, 0.2}, {4, -4, 0.2}, {4, 4, 0.2}, {-4, 4, 0.2},
                                     {-4, -4, 2.8}, {4, -4, 2.8}, {4, 4, 2.8}, {-4, 4, 2.8}};
  BiasDataset data;
  for (int flight = 0; flight < 2; ++flight) {
    for (int step = 0; step < 2000; ++step) {
      const double t = 0.01 * step;
      const Vec3 p(0.5 * std::cos(0.3 * t) + 0.2 * flight, 0.5 * std::sin(0.3 * t), 1.2);
      for (int a = 0; a < 8; ++a) {
        BiasSample s;
        s.t_s = t + 1e-4 * a;
        s.flight = flight;
        s.feature.id_a = a;
        s.feature.id_b = (a + 1) % 8;
        s.feature.w_p_b = p;
        s.feature.w_p_anchor_a = anchors[a];
        s.feature.w_p_anchor_b = anchors[(a + 1) % 8];
        data.samples.push_back(s);
      }
    }
  }
  std::vector<BiasModel::PairMean> means, doubled;
  for (int a = 0; a < 8; ++a) {
    const double c = 0.1 * std::sin(1.7 * a + 0.3);
    means.push_back({a, (a + 1) % 8, c});
    doubled.push_back({a, (a + 1) % 8, 2.0 * c});
  }
  const BiasModel model("z1", FeatureMap::kYawAngles, {}, means);
  const BiasModel twice("z1", FeatureMap::kYawAngles, {}, doubled);
  const BiasModel none("z1", FeatureMap::kYawAngles, {});
  // THEN the level is F23c's statistic on µ, as BiasLevel gives it on the same residuals of one flight (the two
  // flights' levels differ by their geometry only; both are averaged)
  const double level = modelMeanLevel(model, data, 30.0);
  BiasLevel direct(30.0);
  for (const BiasSample& s : data.samples)
    if (s.flight == 0)
      direct.add(s.t_s, s.feature.id_a, s.feature.w_p_anchor_a, s.feature.id_b, s.feature.w_p_anchor_b,
                 s.feature.w_p_b, model.predict(s.feature).mean_m);
  EXPECT_GT(level, 0.02);
  EXPECT_NEAR(level, direct.pairLevelData(), 0.1 * level);
  // AND it scales with the mean, and a model that predicts nothing has none
  EXPECT_NEAR(modelMeanLevel(twice, data, 30.0), 2.0 * level, 1e-9);
  EXPECT_EQ(modelMeanLevel(none, data, 30.0), 0.0);
}

}  // namespace
}  // namespace uwb
