/** @file TdoaBiasVarianceTest.cpp
 *  @brief The bias predictor's variance in the TDoA update: R = noise_scale · σ_tdoa² + variance_m2
 *         (docs/math/gp.md P45; noise_scale = 1 is the paper's R + var_f).
 */
#include <gtest/gtest.h>

#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

struct ConvergedFilter {
  AnchorTable anchors;
  Ekf ekf{EkfParams{}};
  double z_true = 0.0;
};

ConvergedFilter converged() {
  ConvergedFilter s;
  s.anchors.set(0, Vec3(-3, -3, 0.2));
  s.anchors.set(1, Vec3(3, -3, 2.8));
  NavState x;
  x.w_p_b = Vec3(0.2, 0.1, 1.5);
  ErrMat P = initialCovariance(EkfParams{});
  P.block<3, 3>(kPos, kPos) = Mat3::Identity() * 0.01;
  s.ekf.initialize(x, P);
  const Vec3 p_tag = tagPosition(x.w_p_b, x.w_q_b, kUtilTagOffset_b);
  s.z_true = range(p_tag, s.anchors.find(1)->m) - range(p_tag, s.anchors.find(0)->m);
  return s;
}

TEST(TdoaBiasVariance, NoiseScaleScalesTheFilterVarianceOfCorrectedMeasurements) {
  // GIVEN a converged filter and a measurement 0.3 m off, corrected by a predicted bias of 0.1 m
  TdoaUpdateOptions opt;
  opt.sigma_m = 0.3;
  opt.gate_sigma = 0.0;
  const auto run = [&](BiasPrediction b) {
    ConvergedFilter s = converged();
    const BiasPredictor pred = [b](const TdoaFeature&) { return b; };
    return updateTdoa(s.ekf, s.anchors, {0.0, 0, 1, s.z_true + 0.3}, opt, &pred);
  };
  // WHEN the predictor leaves R as is, scales it by 1/4, or adds 0.05 m² to it
  const TdoaUpdateResult paper = run({0.1, 0.0, 1.0});
  const TdoaUpdateResult scaled = run({0.1, 0.0, 0.25});
  const TdoaUpdateResult added = run({0.1, 0.05, 1.0});
  // THEN the innovation is z − 0.1 − ẑ in all three, and S = a P aᵀ + R follows R
  EXPECT_NEAR(paper.innovation_m, 0.2, 1e-9);
  EXPECT_DOUBLE_EQ(scaled.innovation_m, paper.innovation_m);
  const double r2 = paper.innovation_m * paper.innovation_m;
  const double a_P_a = r2 / paper.nis - 0.09;
  EXPECT_GT(a_P_a, 0.0);
  EXPECT_NEAR(r2 / scaled.nis, a_P_a + 0.25 * 0.09, 1e-12);
  EXPECT_NEAR(r2 / added.nis, a_P_a + 0.09 + 0.05, 1e-12);
  // AND an invalid scale leaves the measurement uncorrected
  const TdoaUpdateResult invalid = run({0.1, 0.0, 0.0});
  EXPECT_DOUBLE_EQ(invalid.bias_mean_m, 0.0);
  EXPECT_NEAR(invalid.innovation_m, 0.3, 1e-9);
}

}  // namespace
}  // namespace uwb
