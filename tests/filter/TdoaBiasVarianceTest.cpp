/** @file TdoaBiasVarianceTest.cpp
 *  @brief The bias predictor's variance in the TDoA update: R = noise_scale · σ_tdoa² + variance_m2
 *         (docs/math/gp.md P45; noise_scale = 1 is the paper's R + var_f), and the pose uncertainty of the
 *         correction µ(x̂) (P47): its derivative against the analytic one, as input variance and in the row.
 */
#include <gtest/gtest.h>

#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

/// The default filter without range-bias states (F27): S is then a P aᵀ + R alone, as the expectations below read.
EkfParams plainParams() {
  EkfParams p;
  p.range_bias_sigma_m = 0.0;
  return p;
}

struct ConvergedFilter {
  AnchorTable anchors;
  Ekf ekf{plainParams()};
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

/// µ(p, q) = cᵀp + dᵀ R(q) v: linear in the position, with an attitude dependence whose derivative is known.
struct PoseLinearBias {
  Vec3 c{0.05, -0.02, 0.08};
  Vec3 d{0.03, 0.01, -0.04};
  Vec3 v{1.0, 0.5, -0.2};
};

TEST(TdoaBiasVariance, PoseJacobianOfTheCorrectionMatchesTheAnalyticOne) {
  // GIVEN a predictor µ = cᵀp + dᵀ R v (R recovered from the feature's body-frame anchor vectors, d_b = Rᵀ(a − p))
  // and a tilted, yawed state
  const PoseLinearBias f;
  const Vec3 a_w(-3, -3, 0.2), b_w(3, -3, 2.8);
  const BiasPredictor exact = [f, a_w, b_w](const TdoaFeature& z) {
    const Vec3 wa = (a_w - z.w_p_b).normalized(), wb = (b_w - z.w_p_b).normalized();
    const Vec3 ba = z.b_p_a.normalized(), bb = z.b_p_b.normalized();
    Mat3 W, Bm;
    W << wa, wa.cross(wb).normalized(), wa.cross(wa.cross(wb)).normalized();
    Bm << ba, ba.cross(bb).normalized(), ba.cross(ba.cross(bb)).normalized();
    const Mat3 R = W * Bm.transpose();
    return BiasPrediction{f.c.dot(z.w_p_b) + f.d.dot(R * f.v), 0.0, 1.0};
  };
  NavState x;
  x.w_p_b = Vec3(0.4, -0.3, 1.2);
  x.w_q_b = Quat(Eigen::AngleAxisd(0.7, Vec3::UnitZ()) * Eigen::AngleAxisd(0.1, Vec3::UnitX())).normalized();
  // WHEN differentiating by central differences
  const Eigen::Matrix<double, 1, 6> g = biasPoseJacobian(exact, x, 0, 1, a_w, b_w);
  // THEN ∂µ/∂δp = cᵀ and ∂µ/∂δθ = −dᵀ R [v]× (R(q ⊗ exp(δθ)) ≈ R (I + [δθ]×))
  const Mat3 R = x.w_q_b.toRotationMatrix();
  const Eigen::RowVector3d g_att = -(f.d.transpose() * R * skew(f.v));
  EXPECT_LT((g.head<3>() - f.c.transpose()).norm(), 1e-7);
  EXPECT_LT((g.tail<3>() - g_att).norm(), 1e-7);
}

TEST(TdoaBiasVariance, PoseUncertaintyOfTheCorrectionAsVarianceOrInTheRow) {
  // GIVEN a converged filter (position variance 0.01 m²) and a correction µ = cᵀp
  const Vec3 c(0.3, -0.2, 0.4);
  const BiasPredictor pred = [c](const TdoaFeature& z) { return BiasPrediction{c.dot(z.w_p_b), 0.0, 1.0}; };
  TdoaUpdateOptions opt;
  opt.sigma_m = 0.3;
  opt.gate_sigma = 0.0;
  const auto run = [&](BiasPoseUncertainty mode) {
    ConvergedFilter s = converged();
    opt.bias_pose = mode;
    const TdoaUpdateResult r = updateTdoa(s.ekf, s.anchors, {0.0, 0, 1, s.z_true + 0.3}, opt, &pred);
    return std::make_pair(r, s.ekf.state().w_p_b);
  };
  // WHEN the correction enters as the paper's, with its input variance, or through the row
  const auto [none, p_none] = run(BiasPoseUncertainty::kNone);
  const auto [variance, p_var] = run(BiasPoseUncertainty::kVariance);
  const auto [row, p_row] = run(BiasPoseUncertainty::kJacobian);
  // THEN all three correct by the same µ(x̂); the variance form adds cᵀ P_pp c = 0.01 |c|² to S, and the row form
  // has S = (a + cᵀ) P (a + cᵀ)ᵀ + R, with a the TDoA row of the position (the attitude block of P is tiny)
  EXPECT_DOUBLE_EQ(variance.innovation_m, none.innovation_m);
  EXPECT_DOUBLE_EQ(row.innovation_m, none.innovation_m);
  EXPECT_NEAR(variance.innovation_var_m2 - none.innovation_var_m2, 0.01 * c.squaredNorm(), 1e-6);
  ConvergedFilter s = converged();
  const Vec3 p_tag = tagPosition(s.ekf.state().w_p_b, s.ekf.state().w_q_b, kUtilTagOffset_b);
  const Vec3 a = (p_tag - s.anchors.find(1)->m).normalized() - (p_tag - s.anchors.find(0)->m).normalized();
  const double a_P_a_none = none.innovation_var_m2 - 0.09;
  EXPECT_NEAR(a_P_a_none, 0.01 * a.squaredNorm(), 2e-3);
  EXPECT_NEAR(row.innovation_var_m2 - 0.09, a_P_a_none + 0.01 * (2.0 * a.dot(c) + c.squaredNorm()), 2e-3);
  // AND the larger S of the variance form moves the estimate less
  EXPECT_LT((p_var - s.ekf.state().w_p_b).norm(), (p_none - s.ekf.state().w_p_b).norm());
}

}  // namespace
}  // namespace uwb
