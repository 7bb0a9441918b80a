/** @file BiasPairStructureTest.cpp
 *  @brief Per-anchor-pair structure of the bias model (docs/math/gp.md P28–P29): per-pair constant means
 *         (shrinkage, training on the remainder, prediction, model file), and the anchor-specific eq. 9 kernel
 *         (reduces to the paper kernel for the same anchors; derivatives against finite differences), and the
 *         per-pair eq. 9 + arena-map preset pair-tdoa-pos (P26b).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "support/KernelGradients.h"
#include "support/TestSupport.h"
#include "uwb/eval/BiasModel.h"

namespace uwb {
namespace {

/// A sample of anchor pair (p, p + 1) whose body-frame anchor directions turn with `phase` (rad).
BiasSample pairSample(int p, double phase) {
  BiasSample s;
  s.feature.id_a = p;
  s.feature.id_b = p + 1;
  s.feature.b_p_a = Vec3(3 * std::cos(phase), 3 * std::sin(phase), 1.0);
  s.feature.b_p_b = Vec3(3 * std::cos(phase + 1), 3 * std::sin(phase + 1), -1.0);
  return s;
}

/// Samples of three anchor pairs with constant offsets and white noise; features vary smoothly.
std::vector<BiasSample> offsetSamples(const std::vector<double>& offsets_m, int n_per_pair, double noise_m) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, noise_m);
  std::vector<BiasSample> out;
  for (int k = 0; k < n_per_pair; ++k) {
    for (int p = 0; p < static_cast<int>(offsets_m.size()); ++p) {
      BiasSample s = pairSample(p, 0.01 * k + p);
      s.feature.w_p_anchor_a = Vec3(p, 0, 0);
      s.feature.w_p_anchor_b = Vec3(p + 1, 0, 0);
      s.error_m = offsets_m[p] + noise(rng);
      s.t_s = 0.1 * k;  // 40 s: eight 5 s blocks, every fifth held out
      out.push_back(s);
    }
  }
  return out;
}

/// The defaults with the preset, its number of inducing points and of epochs.
BiasTrainParams trainParams(const std::string& preset, int num_inducing, int epochs) {
  BiasTrainParams tp;
  tp.preset = preset;
  tp.num_inducing = num_inducing;
  tp.svgp.epochs = epochs;
  return tp;
}

TEST(PairMeans, GivenSamplesWhenComputedThenShrunkMeanPerOrderedPair) {
  // GIVEN two samples of pair (0,1) and one of (1,0)
  std::vector<BiasSample> s(3);
  s[0].feature.id_a = 0, s[0].feature.id_b = 1, s[0].error_m = 0.3;
  s[1].feature.id_a = 0, s[1].feature.id_b = 1, s[1].error_m = 0.1;
  s[2].feature.id_a = 1, s[2].feature.id_b = 0, s[2].error_m = -0.5;
  // WHEN the means are computed with n0 = 2 pseudo-samples, and with sample 1 excluded
  const auto m = pairMeans(s, {}, 2.0);
  const auto m_use = pairMeans(s, {true, false, true}, 0.0);
  // THEN m_AB = Σ ε / (n + n0) (P28), ordered pairs kept apart, excluded samples ignored
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].id_a, 0);
  EXPECT_EQ(m[0].id_b, 1);
  EXPECT_NEAR(m[0].mean_m, 0.4 / 4.0, 1e-15);
  EXPECT_NEAR(m[1].mean_m, -0.5 / 3.0, 1e-15);
  EXPECT_NEAR(m_use[0].mean_m, 0.3, 1e-15);
  EXPECT_THROW(pairMeans(s, {}, -1.0), std::invalid_argument);
}

TEST(PairMeans, GivenConstantPairOffsetsWhenTrainedWithPmPresetThenRecoveredAndStoredInTheModelFile) {
  // GIVEN errors that are pair constants plus white noise
  const std::vector<double> offsets{0.25, -0.15, 0.05};
  BiasDataset data;
  data.samples = offsetSamples(offsets, 400, 0.05);
  BiasTrainParams tp = trainParams("tdoa-pm", 10, 3);
  // WHEN the tdoa-pm model is trained
  BiasTrainReport rep;
  const BiasModel model = trainBiasModel(data, tp, &rep);
  // THEN the pair means are close to the offsets, predictions carry them, and the file round trip keeps them
  ASSERT_EQ(model.pairMeans().size(), 3u);
  for (int p = 0; p < 3; ++p) {
    EXPECT_NEAR(model.pairMean(p, p + 1), offsets[p], 0.02) << "pair " << p;
    EXPECT_NEAR(model.predict(data.samples[p].feature).mean_m, offsets[p], 0.05) << "pair " << p;
  }
  EXPECT_EQ(model.pairMean(5, 6), 0.0);
  EXPECT_LT(rep.bias_rmse_after_m, 0.07);
  const BiasModel loaded = BiasModel::fromJson(model.toJson());
  for (const auto& s : data.samples) {
    EXPECT_EQ(loaded.predict(s.feature).mean_m, model.predict(s.feature).mean_m);
  }
  // and a paper preset has no pair means (and files without the key load as before)
  tp.preset = "tdoa";
  const BiasModel plain = trainBiasModel(data, tp);
  EXPECT_TRUE(plain.pairMeans().empty());
  nlohmann::json j = plain.toJson();
  j.erase("pair_means");
  EXPECT_TRUE(BiasModel::fromJson(j).pairMeans().empty());
}

TEST(AnchorTdoaKernel, GivenTheSameAnchorsWhenEvaluatedThenEqualsThePaperKernel) {
  // GIVEN the anchor-specific kernel (P29) and the paper's eq. 9 kernel with the same hyperparameters
  const gp::Kernel ka = BiasPreset::byName("anchor-tdoa").kernel();
  const gp::Kernel kt = BiasPreset::byName("tdoa").kernel();
  ASSERT_EQ(ka.inputDim(), featureDim(FeatureMap::kBodyPositionsAnchors));
  RowVecX x(12), y(12);
  x << 1.0, 2.0, 0.5, -1.0, 3.0, 1.5, 4.0, 0.0, 2.5, 0.0, 4.0, 0.2;
  y << 0.7, 2.2, 0.1, -1.5, 2.0, 1.0, 4.0, 0.0, 2.5, 0.0, 4.0, 0.2;  // same anchors as x
  // WHEN evaluated for the same anchors, and for anchor A 6 m away
  const double k_same = ka(x, y);
  RowVecX y_far = y;
  y_far(6) = -2.0;
  // THEN it equals the paper kernel on the body-frame columns; the slot-A term of another anchor decays by
  // exp(−½ d²/l²) with d = 6 m, l = 1 m (P29), the slot-B term is unchanged
  EXPECT_NEAR(k_same, kt(x.head(6), y.head(6)), 1e-14);
  const gp::Kernel kl_a = gp::Kernel::sum({kt.partSpec(0)});
  const gp::Kernel kl_b = gp::Kernel::sum({kt.partSpec(1)});
  const double expected = kl_a(x.head(6), y.head(6)) * std::exp(-0.5 * 36.0) + kl_b(x.head(6), y.head(6));
  EXPECT_NEAR(ka(x, y_far), expected, 1e-14);
}

TEST(AnchorTdoaKernel, GivenRandomInputsWhenDifferentiatedThenMatchesFiniteDifferences) {
  // GIVEN the anchor-specific kernel with non-default hyperparameters and a few input pairs
  gp::Kernel k = BiasPreset::byName("anchor-tdoa").kernel();
  VecX theta = k.theta();
  for (Eigen::Index i = 0; i < theta.size(); ++i) theta[i] *= 1.0 + 0.1 * static_cast<double>(i % 3);
  k.setTheta(theta);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  MatX X1(4, 12), X2(3, 12);
  for (Eigen::Index i = 0; i < X1.size(); ++i) X1.data()[i] = u(rng);
  for (Eigen::Index i = 0; i < X2.size(); ++i) X2.data()[i] = u(rng);
  X2.block(0, 6, 1, 6) = X1.block(0, 6, 1, 6);  // one pair shares both anchors
  MatX G(4, 3);
  for (Eigen::Index i = 0; i < G.size(); ++i) G.data()[i] = u(rng);
  // WHEN the analytic gradients of Σ G ∘ K w.r.t. θ and X1 are computed
  const test::CrossGradients grad = test::crossGradients(k, X1, X2, G);
  const VecX& g_theta = grad.theta;
  const MatX& g_X1 = grad.x;
  // THEN they match central differences
  const auto objective_theta = [&](const VecX& th) {
    gp::Kernel kk = k;
    kk.setTheta(th);
    VecX out(1);
    out[0] = (G.array() * kk.cross(X1, X2).array()).sum();
    return out;
  };
  // (fixed hyperparameters have no analytic gradient: compare the trainable ones only)
  VecX g_trainable = g_theta;
  const test::JacobianCheck all = test::checkJacobian(objective_theta, k.theta(), g_theta.transpose());
  for (int i = 0; i < k.numParams(); ++i) g_trainable[i] = k.trainable()[i] ? g_theta[i] : all.numerical(0, i);
  const test::JacobianCheck c_theta = test::compareJacobians(g_trainable.transpose(), all.numerical);
  EXPECT_LT(c_theta.max_scaled_error, 1e-6) << c_theta;
  const auto objective_x = [&](const VecX& x) {
    MatX XX = X1;
    XX = Eigen::Map<const MatX>(x.data(), X1.rows(), X1.cols());
    VecX out(1);
    out[0] = (G.array() * k.cross(XX, X2).array()).sum();
    return out;
  };
  const test::JacobianCheck c_x = test::checkJacobian(objective_x, Eigen::Map<const VecX>(X1.data(), X1.size()),
                                                      Eigen::Map<const VecX>(g_X1.data(), g_X1.size()).transpose());
  EXPECT_LT(c_x.relative_error, 1e-6) << c_x;
}

TEST(AnchorTdoaKernel, GivenTheRbfOutputscaleWhenBuiltThenItIsFixed) {
  const gp::Kernel k = BiasPreset::byName("anchor-tdoa-pm").kernel();
  int n_fixed = 0;
  for (int i = 0; i < k.numParams(); ++i) {
    if (k.paramNames()[i].find("rbf.sigma2") != std::string::npos) {
      EXPECT_FALSE(k.trainable()[i]);
      ++n_fixed;
    }
  }
  EXPECT_EQ(n_fixed, 2);
  EXPECT_TRUE(BiasPreset::byName("anchor-tdoa-pm").pair_mean);
  EXPECT_FALSE(BiasPreset::byName("anchor-tdoa").pair_mean);
  EXPECT_FALSE(BiasPreset::byName("tdoa").pair_mean);
}

TEST(PairTdoaPos, GivenTheSamePositionWhenEvaluatedThenThePaperKernelPlusTheMapScale) {
  // GIVEN the pair-tdoa-pos preset: per pair, unnormalized inputs [b_p_a, b_p_b, w_p_b]
  const BiasPreset preset = BiasPreset::byName("pair-tdoa-pos");
  EXPECT_TRUE(preset.per_pair);
  EXPECT_EQ(preset.normalization, gp::InputNormalization::kNone);
  const gp::Kernel k = preset.kernel();
  const gp::Kernel kt = BiasPreset::byName("tdoa").kernel();
  ASSERT_EQ(k.inputDim(), featureDim(FeatureMap::kBodyPositionsWorld));
  TdoaFeature f;
  f.b_p_a = Vec3(1.0, 2.0, 0.5);
  f.b_p_b = Vec3(-1.0, 3.0, 1.5);
  f.w_p_b = Vec3(0.3, -0.2, 1.4);
  RowVecX x(9);
  featureRow(FeatureMap::kBodyPositionsWorld, f, x.data());
  RowVecX expected_row(9);
  expected_row << 1.0, 2.0, 0.5, -1.0, 3.0, 1.5, 0.3, -0.2, 1.4;
  EXPECT_EQ(x, expected_row);
  // WHEN evaluated at the same body position, and 5 m away
  RowVecX y = x;
  y.head(6) << 0.7, 2.2, 0.1, -1.5, 2.0, 1.0;
  RowVecX y_far = y;
  y_far(6) += 5.0;
  // THEN the map adds its outputscale σ² = 0.02 at the same place and (almost) nothing 10 length scales away
  EXPECT_NEAR(k(x, y), kt(x.head(6), y.head(6)) + 0.02, 1e-14);
  EXPECT_NEAR(k(x, y_far), kt(x.head(6), y.head(6)), 1e-12);
}

TEST(PairTdoaPos, GivenAPairErrorThatDependsOnThePositionWhenTrainedThenTheMapLearnsIt) {
  // GIVEN two anchor pairs whose errors are opposite smooth functions of the position (a multipath-like map)
  // plus white noise, with body-frame inputs that do not explain them
  std::vector<BiasSample> samples;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.03);
  for (int k = 0; k < 600; ++k) {
    for (int p = 0; p < 2; ++p) {
      BiasSample s = pairSample(p, 0.37 * k + p);
      s.feature.w_p_b = Vec3(1.5 * std::cos(0.011 * k), 1.5 * std::sin(0.017 * k), 1.2);
      s.error_m = (p == 0 ? 0.2 : -0.2) * std::sin(2.0 * s.feature.w_p_b.x()) + noise(rng);
      s.t_s = 0.1 * k;
      samples.push_back(s);
    }
  }
  BiasDataset data;
  data.samples = samples;
  // WHEN trained
  BiasTrainReport rep;
  const BiasModel model = trainBiasModel(data, trainParams("pair-tdoa-pos", 20, 20), &rep);
  // THEN the held-out bias RMSE falls from ≈ 0.14 m to near the noise, and the file round trip is bit-identical
  EXPECT_GT(rep.bias_rmse_before_m, 0.1);
  EXPECT_LT(rep.bias_rmse_after_m, 0.06);
  const BiasModel loaded = BiasModel::fromJson(model.toJson());
  for (std::size_t i = 0; i < samples.size(); i += 97)
    EXPECT_EQ(loaded.predict(samples[i].feature).mean_m, model.predict(samples[i].feature).mean_m);
}

}  // namespace
}  // namespace uwb
