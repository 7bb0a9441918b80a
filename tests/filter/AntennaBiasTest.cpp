/** @file AntennaBiasTest.cpp
 *  @brief The antenna-pattern TDoA bias learned in flight (docs/math/filter.md F25): the spherical-harmonic basis,
 *         the learner on its own, and the estimator on synthetic flights with and without an antenna pattern.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "FilterTestUtil.h"
#include "uwb/filter/AntennaBias.h"
#include "uwb/filter/TdoaLocalizer.h"

namespace uwb {
namespace {

using filtertest::Truth;

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n), exact for polynomials up to degree 2n − 1.
void gaussLegendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double step = p1 / dp;
      z -= step;
      if (std::abs(step) < 1e-15) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

TEST(AntennaBasis, IsOrthonormalOnTheSphere) {
  // GIVEN a product quadrature (Gauss–Legendre in z, uniform in azimuth) exact for polynomials of degree ≤ 8
  std::vector<double> z, wz;
  gaussLegendre(8, z, wz);
  const int n_az = 16;
  for (int degree = 2; degree <= kMaxAntennaDegree; ++degree) {
    SCOPED_TRACE(degree);
    const int n = antennaBasisSize(degree);
    // WHEN we integrate φ φᵀ over the sphere
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t i = 0; i < z.size(); ++i) {
      const double r = std::sqrt(1.0 - z[i] * z[i]);
      for (int k = 0; k < n_az; ++k) {
        const double az = 2.0 * kPi * k / n_az;
        const AntennaVec phi = antennaBasis(Vec3(r * std::cos(az), r * std::sin(az), z[i]), degree);
        G += (wz[i] * 2.0 * kPi / n_az) * phi * phi.transpose();
      }
    }
    // THEN the Gram matrix is the identity: ∫ Y_lm Y_l'm' dΩ = δ
    EXPECT_LT((G - Eigen::MatrixXd::Identity(n, n)).cwiseAbs().maxCoeff(), 1e-12) << G;
  }
}

TEST(AntennaBasis, KnownValuesAndSizes) {
  // GIVEN the basis sizes of degrees 2…4 and the zonal harmonics at the pole
  EXPECT_EQ(antennaBasisSize(2), 5);
  EXPECT_EQ(antennaBasisSize(3), 12);
  EXPECT_EQ(antennaBasisSize(4), 21);
  EXPECT_THROW(antennaBasisSize(1), std::invalid_argument);
  const AntennaVec phi = antennaBasis(Vec3::UnitZ(), 4);
  // THEN Y_l0(north pole) = √((2l + 1)/4π) and every other order vanishes there
  EXPECT_NEAR(phi(2), std::sqrt(5.0 / (4.0 * kPi)), 1e-12);
  EXPECT_NEAR(phi(8), std::sqrt(7.0 / (4.0 * kPi)), 1e-12);
  EXPECT_NEAR(phi(16), std::sqrt(9.0 / (4.0 * kPi)), 1e-12);
  EXPECT_NEAR(phi.cwiseAbs().sum(), phi(2) + phi(8) + phi(16), 1e-12);
  // AND even degrees are even, odd degrees odd under u → −u (so the pattern is not a position offset, F25a)
  const Vec3 u = Vec3(0.3, -0.5, 0.8).normalized();
  const AntennaVec p = antennaBasis(u, 4), m = antennaBasis(-u, 4);
  EXPECT_LT((p.head(5) - m.head(5)).norm(), 1e-12);
  EXPECT_LT((p.segment(5, 7) + m.segment(5, 7)).norm(), 1e-12);
  EXPECT_LT((p.tail(9) - m.tail(9)).norm(), 1e-12);
}

TdoaFeature featureAt(const Vec3& w_p_b, const Quat& w_q_b, int id_a, int id_b) {
  const AnchorTable anchors = filtertest::arenaAnchors();
  return makeTdoaFeature(id_a, id_b, w_p_b, w_q_b, anchors.find(id_a)->m, anchors.find(id_b)->m);
}

TEST(OnlineAntennaBias, PositionRowMatchesCentralDifferences) {
  // GIVEN a TDoA feature away from both anchors
  const Vec3 w_p_b(0.4, -1.1, 1.3);
  const TdoaFeature f = featureAt(w_p_b, Quat::Identity(), 2, 5);
  // WHEN we compare the analytic ∂z/∂p (F25e) with central differences of z(p) = |p − a_B| − |p − a_A|
  const Vec3 J = OnlineAntennaBias::positionRow(f);
  const auto z = [&](const Vec3& p) { return (p - f.w_p_anchor_b).norm() - (p - f.w_p_anchor_a).norm(); };
  Vec3 J_num;
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i) {
    const Vec3 e = Vec3::Unit(i) * h;
    J_num(i) = (z(w_p_b + e) - z(w_p_b - e)) / (2.0 * h);
  }
  // THEN they agree
  EXPECT_TRUE(J.isApprox(J_num, 1e-7)) << J.transpose() << "\nvs\n" << J_num.transpose();
}

TEST(OnlineAntennaBias, RegressorIsTheDifferenceOfTheBodyFrameDirections) {
  // GIVEN a rotated body and the learner with the Crazyflie tag offset
  const Quat w_q_b(Eigen::AngleAxisd(0.7, Vec3(0.2, 0.1, 1.0).normalized()));
  const Vec3 w_p_b(0.5, 0.2, 1.4);
  const TdoaFeature f = featureAt(w_p_b, w_q_b, 1, 6);
  const AntennaBiasParams params;
  const OnlineAntennaBias learner(params);
  // WHEN we form the regressor
  const AntennaVec h = learner.regressor(f);
  // THEN it is φ(u_B) − φ(u_A) with u the body-frame direction from the tag to each anchor
  const Vec3 w_p_tag = w_p_b + w_q_b * params.b_t_tag;
  const Vec3 u_a = (w_q_b.conjugate() * (f.w_p_anchor_a - w_p_tag)).normalized();
  const Vec3 u_b = (w_q_b.conjugate() * (f.w_p_anchor_b - w_p_tag)).normalized();
  const AntennaVec expected = antennaBasis(u_b, params.max_degree) - antennaBasis(u_a, params.max_degree);
  EXPECT_LT((h - expected).norm(), 1e-9);
}

TEST(OnlineAntennaBias, RecoversAPatternFromItsTdoaAndForgetsTowardsThePrior) {
  // GIVEN a degree-3 pattern θ* and noise-free TDoA biases h(u)ᵀθ* seen from random poses (no position offset)
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  AntennaBiasParams params;
  params.offset_sigma_m = 0.0;
  params.memory_s = 10.0;
  OnlineAntennaBias learner(params);
  AntennaVec theta_true(learner.size());
  for (int i = 0; i < learner.size(); ++i) theta_true(i) = 0.1 * n(rng);
  // WHEN it learns from 3000 TDoA over 3 s with a small innovation variance
  for (int k = 0; k < 3000; ++k) {
    const Quat q(Eigen::AngleAxisd(kPi * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()));
    const TdoaFeature f = featureAt(Vec3(2.0 * u(rng), 2.0 * u(rng), 1.5 + u(rng)), q, k % 8, (k + 3) % 8);
    learner.advance(0.001 * k);
    const BiasPrediction b = learner.predict(f);
    learner.learn(learner.regressor(f).dot(theta_true) - b.mean_m, 1e-4);
  }
  // THEN the coefficients are found
  EXPECT_LT((learner.coefficients() - theta_true).norm(), 0.02 * theta_true.norm());
  // AND after many memory times without data they return to the prior N(0, σ² I)
  learner.advance(3.0 + 50.0 * params.memory_s);
  EXPECT_LT(learner.coefficients().norm(), 1e-9);
  EXPECT_NEAR(learner.covariance()(0, 0), params.prior_sigma_m * params.prior_sigma_m, 1e-12);
}

/// Level flight on a circle of radius 1.5 m around (0.5, 0) with a ±0.4 m height sine, 90 s.
Truth circleTruth(double t) {
  const double w = 0.5, wz = 0.37;
  return {Vec3(0.5 + 1.5 * std::cos(w * t), 1.5 * std::sin(w * t), 1.3 + 0.4 * std::sin(wz * t)),
          Vec3(-1.5 * w * std::sin(w * t), 1.5 * w * std::cos(w * t), 0.4 * wz * std::cos(wz * t)),
          Vec3(-1.5 * w * w * std::cos(w * t), -1.5 * w * w * std::sin(w * t), -0.4 * wz * wz * std::sin(wz * t))};
}

/// RMSE of the position over the second half of a synthetic circle flight with TDoA bias d(u_B) − d(u_A)
/// for the antenna pattern `theta` (degrees 2–3; zero: no bias), with or without learning it (noise_scale: F25d).
double secondHalfRmse(const AntennaVec& theta, bool learn, unsigned seed, double noise_scale) {
  const AnchorTable anchors = filtertest::arenaAnchors();
  const double t_end = 90.0;
  const auto offset = [&](double t, int id_a) {
    // the log's pairs are (k, k + 1 mod 8); a level body: body-frame directions are world directions
    const int id_b = (id_a + 1) % 8;
    const Vec3 p_tag = circleTruth(t).p + kUtilTagOffset_b;
    const Vec3 u_a = (anchors.find(id_a)->m - p_tag).normalized(), u_b = (anchors.find(id_b)->m - p_tag).normalized();
    return (antennaBasis(u_b, 3) - antennaBasis(u_a, 3)).dot(theta);
  };
  const SensorLog log = filtertest::flightLog(anchors, circleTruth, 0.0, t_end, 0.1, true, seed, offset);
  EkfParams params;
  params.ground_phase = GroundPhase::kNone;
  // the learner as measured in F25: beside a filter without range-bias states (F27), whose white TDoA std stands for
  // the whole error
  params.range_bias_sigma_m = 0.0;
  params.tdoa_sigma_m = 0.35;
  if (learn) {
    params.antenna_bias_degree = 3;
    params.antenna_bias_noise_scale = noise_scale;
  }
  const LocalizerResult r = TdoaLocalizer(params, anchors).run(log);
  double sq = 0.0;
  int n = 0;
  for (const LocalizerEstimate& e : r.estimates) {
    if (e.t_s < 0.5 * t_end) continue;
    sq += (e.x.w_p_b - circleTruth(e.t_s).p).squaredNorm();
    ++n;
  }
  EXPECT_GT(n, 100);
  return std::sqrt(sq / n);
}

TEST(OnlineAntennaBias, LearningAnAntennaPatternReducesTheError) {
  // GIVEN a synthetic flight whose TDoA carry a degree-2–3 antenna pattern of RMS ≈ 0.1 m over the sphere
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  AntennaVec theta(antennaBasisSize(3));
  for (int i = 0; i < theta.size(); ++i) theta(i) = 0.1 * n(rng);
  // WHEN the estimator runs without and with learning the pattern in flight
  // (noise scale 1: the synthetic TDoA noise is white)
  const double plain = secondHalfRmse(theta, false, 11, 1.0);
  const double learned = secondHalfRmse(theta, true, 11, 1.0);
  RecordProperty("plain_rmse_mm", static_cast<int>(1000.0 * plain));
  RecordProperty("learned_rmse_mm", static_cast<int>(1000.0 * learned));
  // THEN learning it reduces the error over the second half of the flight
  EXPECT_LT(learned, 0.8 * plain) << "plain " << plain << " learned " << learned;
}

TEST(OnlineAntennaBias, ChangesNothingMuchWithoutBias) {
  // GIVEN a synthetic flight with white TDoA noise only
  const AntennaVec zero = AntennaVec::Zero(antennaBasisSize(3));
  // WHEN the estimator runs without and with learning, with the default noise scale and with the white-noise one
  const double plain = secondHalfRmse(zero, false, 12, 1.0);
  const double learned = secondHalfRmse(zero, true, 12, EkfParams{}.antenna_bias_noise_scale);
  const double learned_fast = secondHalfRmse(zero, true, 12, 1.0);
  RecordProperty("plain_rmse_um", static_cast<int>(1e6 * plain));
  RecordProperty("learned_rmse_um", static_cast<int>(1e6 * learned));
  RecordProperty("learned_fast_rmse_um", static_cast<int>(1e6 * learned_fast));
  // THEN the error stays within 2 % with the default, and within 2 % and a millimetre learning 1000 times faster
  EXPECT_LT(learned, 1.02 * plain) << "plain " << plain << " learned " << learned;
  EXPECT_LT(learned_fast, 1.02 * plain + 0.001) << "plain " << plain << " learned " << learned_fast;
}

TEST(OnlineAntennaBias, OffByDefault) {
  // GIVEN the default parameters
  const EkfParams params;
  // THEN no pattern is learned, and the estimator has no learner
  EXPECT_EQ(params.antenna_bias_degree, 0);
  const Estimator est(params, filtertest::arenaAnchors());
  EXPECT_EQ(est.antennaBias(), nullptr);
  // AND degree 1 is refused (a position offset, F25a)
  EkfParams bad = params;
  bad.antenna_bias_degree = 1;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
