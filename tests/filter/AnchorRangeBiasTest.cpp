/** @file AnchorRangeBiasTest.cpp
 *  @brief Per-anchor range-bias states (docs/math/filter.md F27): the Ornstein–Uhlenbeck transition, the augmented
 *         correction and propagation against dense references, and what the states learn on synthetic flights.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <initializer_list>
#include <random>

#include "FilterTestUtil.h"
#include "uwb/filter/AnchorRangeBias.h"
#include "uwb/filter/Ekf.h"
#include "uwb/filter/QuadImuProcess.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/SensorEvents.h"
#include "uwb/filter/TdoaUpdate.h"

namespace uwb {
namespace {

EkfParams rangeBiasParams(double sigma_m = 0.2, double tau_s = 2.0) {
  EkfParams p;
  p.range_bias_sigma_m = sigma_m;
  p.range_bias_tau_s = tau_s;
  return p;
}

/// A random symmetric positive-definite 15 × 15 covariance of a plausible scale.
ErrMat randomCovariance(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  ErrMat A;
  for (int i = 0; i < kDim; ++i)
    for (int j = 0; j < kDim; ++j) A(i, j) = 0.1 * n(rng);
  return A * A.transpose() + 0.01 * ErrMat::Identity();
}

NavState hoverState() {
  NavState x;
  x.w_p_b = Vec3(0.4, -0.2, 1.3);
  x.w_v_b = Vec3(0.3, 0.1, 0.0);
  x.w_q_b = expQuat(Vec3(0.02, -0.01, 0.3));
  return x;
}

/// A filter with range-bias states whose blocks are correlated with δx by the TDoA corrections `warmup` (no gate, no
/// robust weight), from a random covariance; the TDoA options used are returned in `opt`.
Ekf correlatedFilter(const EkfParams& params, unsigned seed, std::initializer_list<TdoaMeasurement> warmup,
                     TdoaUpdateOptions* opt) {
  Ekf ekf(params);
  ekf.initialize(hoverState(), randomCovariance(seed));
  opt->gate_sigma = 0.0;
  opt->loss = RobustLoss::kNone;
  const AnchorTable anchors = filtertest::arenaAnchors();
  for (const TdoaMeasurement& z : warmup) updateTdoa(ekf, anchors, z, *opt);
  return ekf;
}

TEST(AnchorRangeBias, SlotsAreGivenOnFirstSightUntilFull) {
  AnchorRangeBias b(0.2, 2.0);
  EXPECT_EQ(b.findSlot(7), -1);
  EXPECT_EQ(b.slot(7), 0);
  EXPECT_EQ(b.slot(3), 1);
  EXPECT_EQ(b.slot(7), 0);
  for (int id = 100; id < 100 + kMaxBiasAnchors - 2; ++id) EXPECT_GE(b.slot(id), 0);
  EXPECT_EQ(b.slot(999), -1);  // full: this anchor has no state
  EXPECT_DOUBLE_EQ(b.mean(999), 0.0);
  EXPECT_DOUBLE_EQ(b.stddev(999), 0.2);
  EXPECT_THROW(AnchorRangeBias(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(AnchorRangeBias(0.1, -1.0), std::invalid_argument);
}

TEST(AnchorRangeBias, DecayIsTheOrnsteinUhlenbeckTransitionAndComposes) {
  // GIVEN a state with a mean, a cross-covariance and a correlated bias block (from a correction)
  TdoaUpdateOptions opt;
  const Ekf ekf = correlatedFilter(rangeBiasParams(0.2, 2.0), 1, {{0.0, 0, 1, 0.7}}, &opt);
  AnchorRangeBias once = *ekf.rangeBias(), twice = *ekf.rangeBias();
  // WHEN decaying over 0.3 s at once, or over 0.1 s and then 0.2 s
  once.decay(0.3);
  twice.decay(0.1);
  twice.decay(0.2);
  // THEN both are the same, the mean and the cross terms shrink by e^{−T/τ} and the variance relaxes towards σ²
  const double f = std::exp(-0.3 / 2.0);
  const AnchorRangeBias& before = *ekf.rangeBias();
  EXPECT_LT((once.means() - twice.means()).norm(), 1e-14);
  EXPECT_LT((once.covariance() - twice.covariance()).norm(), 1e-14);
  EXPECT_LT((once.cross() - twice.cross()).norm(), 1e-14);
  EXPECT_LT((once.means() - f * before.means()).norm(), 1e-14);
  EXPECT_LT((once.cross() - f * before.cross()).norm(), 1e-14);
  const BiasMat expected = f * f * before.covariance() + (1.0 - f * f) * 0.04 * BiasMat::Identity();
  EXPECT_LT((once.covariance() - expected).norm(), 1e-14);
  EXPECT_NE(before.means()(0), 0.0);  // the correction did move the biases
}

TEST(EkfRangeBias, TdoaCorrectionIsTheKalmanUpdateOfTheAugmentedState) {
  // GIVEN a filter with range-bias states correlated with δx by earlier corrections
  TdoaUpdateOptions opt;
  Ekf ekf = correlatedFilter(rangeBiasParams(), 2,
                             {{0.0, 0, 1, 0.4}, {0.0, 1, 2, -0.9}, {0.0, 2, 3, 1.3}, {0.0, 7, 0, 0.2}}, &opt);
  const AnchorTable anchors = filtertest::arenaAnchors();
  const AugMat J0 = ekf.rangeBias()->joint(ekf.covariance());
  const BiasVec beta0 = ekf.rangeBias()->means();
  const NavState x0 = ekf.state();
  // WHEN one more TDoA of pair (1, 2) is applied
  const TdoaMeasurement z{0.0, 1, 2, -0.75};
  const TdoaUpdateResult r = updateTdoa(ekf, anchors, z, opt);
  ASSERT_EQ(r.outcome, UpdateOutcome::kApplied);
  // THEN it equals the dense Kalman update on [δx, δβ] with the row [∂h/∂δx, −e_A + e_B] (F27c)
  const std::optional<ScalarLinearMessage<kDim>> m =
      tdoaMessage(x0, anchors, z, z.tdoa_m - (beta0(2) - beta0(1)), opt.sigma_m * opt.sigma_m, opt.b_t_tag);
  ASSERT_TRUE(m.has_value());
  Eigen::Matrix<double, 1, kAugDim> h = Eigen::Matrix<double, 1, kAugDim>::Zero();
  h.head<kDim>() = m->a;
  h(kDim + 1) = -1.0;  // anchor 1 (slot 1) is A
  h(kDim + 2) = 1.0;   // anchor 2 (slot 2) is B
  const double S = (h * J0 * h.transpose())(0, 0) + m->var;
  const AugVec K = J0 * h.transpose() / S;
  const AugVec dx = K * m->y;
  const AugMat J1 = J0 - K * S * K.transpose();
  EXPECT_NEAR(r.innovation_var_m2, S, 1e-12);
  EXPECT_LT((ekf.state().w_p_b - (x0.w_p_b + dx.segment<3>(kPos))).norm(), 1e-12);
  EXPECT_LT((ekf.rangeBias()->means() - (beta0 + dx.tail<kMaxBiasAnchors>())).norm(), 1e-12);
  EXPECT_LT((ekf.rangeBias()->joint(ekf.covariance()) - J1).norm(), 1e-12);
  // and the graph's equality node (G18) on the 31-dimensional joint state, the plain reference of the block update
  ScalarLinearMessage<kAugDim> m_aug;
  m_aug.a = h;
  m_aug.y = m->y;
  m_aug.var = m->var;
  AugMat J_node = J0;
  AugVec dx_node = AugVec::Zero();
  ASSERT_TRUE(equalityRankOneInPlace<kAugDim>(dx_node, J_node, m_aug).has_value());
  EXPECT_LT((ekf.rangeBias()->joint(ekf.covariance()) - J_node).norm(), 1e-12);
  EXPECT_LT((dx_node - dx).norm(), 1e-12);
}

/// The dense Kalman update of the joint state [δx, δβ] with covariance J by the scalar row h, innovation y, variance r.
void denseUpdate(AugMat& J, AugVec& dx, const Eigen::Matrix<double, 1, kAugDim>& h, double y, double r) {
  const double S = (h * J * h.transpose())(0, 0) + r;
  const AugVec K = J * h.transpose() / S;
  dx += K * (y - (h * dx)(0, 0));
  J -= K * S * K.transpose();
}

TEST(EkfRangeBias, MessagesOnTheStateAloneMoveTheBiasesThroughTheCrossCovariance) {
  // GIVEN a filter with correlated range-bias states
  TdoaUpdateOptions opt;
  Ekf ekf = correlatedFilter(rangeBiasParams(), 6, {{0.0, 0, 1, 0.4}, {0.0, 3, 4, -0.6}, {0.0, 5, 6, 0.9}}, &opt);
  AugMat J = ekf.rangeBias()->joint(ekf.covariance());
  const BiasVec beta0 = ekf.rangeBias()->means();
  const NavState x0 = ekf.state();
  // WHEN a height and the zero-velocity messages (rows on δp and δv only, F14, F22) are applied
  ekf.positionUpdate(2, 1.1, 0.05);
  ekf.zeroVelocityUpdate(0.02);
  // THEN they are the dense Kalman updates of [δx, δβ] (F27c): β̂ moves although no row reaches it
  AugVec dx = AugVec::Zero();
  Eigen::Matrix<double, 1, kAugDim> h = Eigen::Matrix<double, 1, kAugDim>::Zero();
  h(kPos + 2) = 1.0;
  denseUpdate(J, dx, h, 1.1 - x0.w_p_b.z(), 0.05 * 0.05);
  for (int i = 0; i < 3; ++i) {
    h.setZero();
    h(kVel + i) = 1.0;
    denseUpdate(J, dx, h, -x0.w_v_b(i), 0.02 * 0.02);
  }
  EXPECT_LT((ekf.rangeBias()->joint(ekf.covariance()) - J).norm(), 1e-10);
  EXPECT_LT((ekf.rangeBias()->means() - (beta0 + dx.tail<kMaxBiasAnchors>())).norm(), 1e-10);
  EXPECT_GT(dx.tail<kMaxBiasAnchors>().norm(), 1e-6);
  EXPECT_LT((ekf.state().w_v_b - (x0.w_v_b + dx.segment<3>(kVel))).norm(), 1e-10);
}

TEST(EkfRangeBias, ImuPropagationIsTheAugmentedTransition) {
  // GIVEN a filter with cross-covariances, and the same IMU steps accumulated by hand
  EkfParams params = rangeBiasParams(0.25, 1.5);
  TdoaUpdateOptions opt;
  Ekf ekf = correlatedFilter(params, 3, {{0.0, 3, 4, 0.5}, {0.0, 5, 6, -0.2}}, &opt);
  const CrossMat cross0 = ekf.rangeBias()->cross();
  const BiasMat Pbb0 = ekf.rangeBias()->covariance();
  Ekf plain(EkfParams{});  // the same filter without range-bias states gives the δx block
  plain.initialize(ekf.state(), ekf.covariance());
  AccumulatedTransition phi;
  NavState x = ekf.state();
  ImuReading imu;
  imu.b_acc_mps2 = Vec3(0.3, -0.2, kGravity_mps2 + 0.4);
  imu.b_gyro_radps = Vec3(0.05, -0.02, 0.3);
  const int steps = 20;
  const double dt = 0.001;
  for (int k = 0; k < steps; ++k) {
    ekf.predict(imu, dt);
    plain.predict(imu, dt);
    const ProcessStep s = quadImuProcess(x, imu, dt, params.accel_model, params.rotor_drag_per_s);
    x = s.next;
    phi.accumulate(s.J);
  }
  // WHEN the covariance is propagated
  ekf.propagateCovariance();
  plain.propagateCovariance();
  // THEN P_xx is the plain filter's, P_xβ = Φ P_xβ f and P_ββ = f² P_ββ + (1 − f²) σ² I (F27b)
  const double f = std::exp(-steps * dt / 1.5);
  EXPECT_LT((ekf.covariance() - plain.covariance()).norm(), 1e-12);
  EXPECT_LT((ekf.rangeBias()->cross() - phi.dense() * cross0 * f).norm(), 1e-12);
  const BiasMat expected = f * f * Pbb0 + (1.0 - f * f) * 0.0625 * BiasMat::Identity();
  EXPECT_LT((ekf.rangeBias()->covariance() - expected).norm(), 1e-12);
}

TEST(EkfRangeBias, TdoaOnlyPropagationIsTheAugmentedTransition) {
  // GIVEN a TDoA-only (constant-velocity) filter with cross-covariances
  EkfParams params = rangeBiasParams(0.2, 3.0);
  params.process_model = ProcessModel::kConstantVelocity;
  TdoaUpdateOptions opt;
  Ekf ekf = correlatedFilter(params, 4, {{0.0, 2, 3, 0.1}}, &opt);
  const CrossMat cross0 = ekf.rangeBias()->cross();
  // WHEN 0.05 s pass
  const double T = 0.05;
  ekf.predictTdoaOnly(T);
  ekf.propagateCovariance();
  // THEN P_xβ = F(T) P_xβ e^{−T/τ} with F(T) = I + T E_pv (F9)
  ErrMat F = ErrMat::Identity();
  F.block<3, 3>(kPos, kVel) = T * Mat3::Identity();
  EXPECT_LT((ekf.rangeBias()->cross() - F * cross0 * std::exp(-T / 3.0)).norm(), 1e-12);
}

TEST(AnchorRangeBias, AdaptedStdFollowsThePosteriorSecondMomentWithinItsBounds) {
  // GIVEN bias states whose first two anchors were corrected to a near-zero posterior (β̂ = 0, P_kk ≈ 0)
  const auto corrected = []() {
    AnchorRangeBias b(0.1, 0.5);
    b.slot(10);
    b.slot(11);
    for (const int k : {0, 1}) {
      BiasVec w = BiasVec::Zero();
      w(k) = std::sqrt(b.covariance()(k, k) - 1e-8);
      b.downdate(ErrVec::Zero(), w, BiasVec::Zero());
    }
    return b;
  };
  // WHEN nothing adapts, the std is the constructor's
  AnchorRangeBias fixed = corrected();
  fixed.decay(0.01);
  fixed.adapt(0, 1);
  EXPECT_DOUBLE_EQ(fixed.adaptedSigma(), 0.1);
  // WHEN adapting (time constant 0.3 s) after each 10 ms step while the posterior stays near zero
  AnchorRangeBias b = corrected();
  b.enableAdaptation(0.3, 0.2);
  double previous = b.adaptedSigma();
  for (int k = 0; k < 300; ++k) {
    b.decay(0.01);
    BiasVec w = BiasVec::Zero();  // keep correcting both anchors
    w(0) = std::sqrt(std::max(b.covariance()(0, 0) - 1e-8, 0.0));
    b.downdate(ErrVec::Zero(), w, BiasVec::Zero());
    w.setZero();
    w(1) = std::sqrt(std::max(b.covariance()(1, 1) - 1e-8, 0.0));
    b.downdate(ErrVec::Zero(), w, BiasVec::Zero());
    b.adapt(0, 1);
    EXPECT_LE(b.adaptedSigma(), previous + 1e-15);  // (F27e) it only falls while the evidence says there is no bias
    previous = b.adaptedSigma();
  }
  // THEN the std falls to its floor and not below; an anchor without a slot has the adapted prior
  EXPECT_NEAR(b.adaptedSigma(), 0.02, 1e-12);
  EXPECT_NEAR(b.stddev(99), 0.02, 1e-12);
  EXPECT_DOUBLE_EQ(b.sigma(), 0.1);
  // WHEN the anchors then show a bias of 0.3 m (β̂ = ±0.3)
  BiasVec dbeta = BiasVec::Zero();
  dbeta(0) = 0.3;
  dbeta(1) = -0.3;
  b.downdate(ErrVec::Zero(), BiasVec::Zero(), dbeta);
  for (int k = 0; k < 100; ++k) {
    b.decay(0.01);
    b.adapt(0, 1);
  }
  // THEN the std grows back, up to the constructor's and not above
  EXPECT_DOUBLE_EQ(b.adaptedSigma(), 0.1);
  EXPECT_DOUBLE_EQ(b.stddev(99), 0.1);
  EXPECT_THROW(b.enableAdaptation(-1.0, 0.2), std::invalid_argument);
  EXPECT_THROW(b.enableAdaptation(1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(b.enableAdaptation(1.0, 1.5), std::invalid_argument);
}

TEST(EkfRangeBias, ResetsClearTheCrossCovarianceOfWhatTheyReset) {
  TdoaUpdateOptions opt;
  Ekf ekf = correlatedFilter(rangeBiasParams(), 5, {{0.0, 0, 1, 0.3}}, &opt);
  ASSERT_GT(ekf.rangeBias()->cross().middleRows<3>(kPos).norm(), 0.0);
  ekf.resetPosition(Vec3(1, 2, 1), 0.5);
  EXPECT_EQ(ekf.rangeBias()->cross().middleRows<3>(kPos).norm(), 0.0);
  EXPECT_GT(ekf.rangeBias()->cross().middleRows<3>(kAtt).norm(), 0.0);
  // a covariance intersection's P/ω scales the whole joint covariance
  const AugMat J = ekf.rangeBias()->joint(ekf.covariance());
  ekf.scaleCovariance(2.0);
  EXPECT_LT((ekf.rangeBias()->joint(ekf.covariance()) - 2.0 * J).norm(), 1e-12);
}

TEST(EkfRangeBias, AHeightResetClearsTheHeightsCorrelationsAndNothingElse) {
  // GIVEN a filter whose position is correlated with the range biases and with its other states
  TdoaUpdateOptions opt;
  Ekf ekf = correlatedFilter(rangeBiasParams(), 5, {{0.0, 0, 1, 0.3}, {0.0, 1, 2, -0.2}}, &opt);
  const ErrMat P0 = ekf.covariance();
  const Vec3 p0 = ekf.state().w_p_b;
  ASSERT_GT(ekf.rangeBias()->cross().row(kPos + 2).norm(), 0.0);
  ASSERT_GT(std::abs(P0(kPos, kPos + 2)), 0.0);
  // WHEN the height is overwritten (F29c: the TDoA's own height after they overrule the floor)
  ekf.resetHeight(1.3, 0.04);
  // THEN the height and its variance are the given ones, uncorrelated with anything; x, y and the rest are untouched
  const ErrMat& P = ekf.covariance();
  EXPECT_EQ(ekf.state().w_p_b.z(), 1.3);
  EXPECT_EQ(ekf.state().w_p_b.head<2>(), p0.head<2>());
  EXPECT_EQ(P(kPos + 2, kPos + 2), 0.04);
  EXPECT_EQ(P.row(kPos + 2).norm(), 0.04);
  EXPECT_EQ(P.col(kPos + 2).norm(), 0.04);
  EXPECT_EQ(ekf.rangeBias()->cross().row(kPos + 2).norm(), 0.0);
  EXPECT_GT(ekf.rangeBias()->cross().row(kPos).norm(), 0.0);
  ErrMat rest = P, rest0 = P0;
  for (ErrMat* m : {&rest, &rest0}) {
    m->row(kPos + 2).setZero();
    m->col(kPos + 2).setZero();
  }
  EXPECT_EQ((rest - rest0).norm(), 0.0);
}

TEST(EkfRangeBias, InflationAlongThePositionIsTheDenseFormulaOnTheJointCovariance) {
  // GIVEN a filter whose joint covariance over [δx, δβ] is correlated with the position
  TdoaUpdateOptions opt;
  Ekf ekf = correlatedFilter(rangeBiasParams(), 7, {{0.0, 0, 1, 0.3}, {0.0, 1, 2, -0.2}}, &opt);
  ASSERT_GT(ekf.rangeBias()->cross().middleRows<3>(kPos).norm(), 0.0);
  const AugMat J = ekf.rangeBias()->joint(ekf.covariance());
  // WHEN it is inflated along the position by f (a covariance intersection's weight ω = 1/f, G21)
  const double f = 2.5;
  ASSERT_TRUE(ekf.inflateAlongPosition(f));
  const AugMat J2 = ekf.rangeBias()->joint(ekf.covariance());
  // THEN it is J + (f − 1) J_·p J_pp⁻¹ J_p· computed densely
  const Eigen::Matrix<double, kAugDim, 3> G = J.middleCols<3>(kPos);
  const AugMat expected = J + (f - 1.0) * G * J.block<3, 3>(kPos, kPos).inverse() * G.transpose();
  EXPECT_LT((J2 - expected).cwiseAbs().maxCoeff(), 1e-12 * J.cwiseAbs().maxCoeff());
  // AND the position block is f times the prior, and the covariance of the other states given the position (their
  // Schur complement) is unchanged
  EXPECT_LT((J2.block<3, 3>(kPos, kPos) - f * J.block<3, 3>(kPos, kPos)).norm(), 1e-12);
  const auto schur = [](const AugMat& A) {
    Eigen::Matrix<double, kAugDim - 3, kAugDim> R;  // every row but the position's
    int r = 0;
    for (int i = 0; i < kAugDim; ++i)
      if (i < kPos || i >= kPos + 3) R.row(r++) = A.row(i);
    Eigen::Matrix<double, kAugDim - 3, kAugDim - 3> rest;
    Eigen::Matrix<double, kAugDim - 3, 3> cross = R.middleCols<3>(kPos);
    int c = 0;
    for (int j = 0; j < kAugDim; ++j)
      if (j < kPos || j >= kPos + 3) rest.col(c++) = R.col(j);
    return Eigen::Matrix<double, kAugDim - 3, kAugDim - 3>(
        rest - cross * A.block<3, 3>(kPos, kPos).inverse() * cross.transpose());
  };
  EXPECT_LT((schur(J2) - schur(J)).cwiseAbs().maxCoeff(), 1e-10);
  // AND f ≤ 1 does nothing
  Ekf same = ekf;
  EXPECT_FALSE(same.inflateAlongPosition(1.0));
  EXPECT_EQ(same.covariance(), ekf.covariance());
}

/// Circle of radius 1.2 m at 1.4 m height, 0.6 rad/s.
filtertest::Truth circle(double t) {
  const double w = 0.6, r = 1.2;
  return {Vec3(r * std::cos(w * t), r * std::sin(w * t), 1.4), Vec3(-r * w * std::sin(w * t), r * w * std::cos(w * t), 0),
          Vec3(-r * w * w * std::cos(w * t), -r * w * w * std::sin(w * t), 0)};
}

/// Runs an Estimator over the log one event at a time; RMSE of the position against circle() after t0_s.
/// after_tdoa(t) is called after each TDoA.
double runCircle(Estimator& est, const SensorLog& log, double t0_s,
                 const std::function<void(double)>& after_tdoa = {}) {
  double s = 0.0;
  int n = 0;
  SensorEventCursor cursor(log);
  for (SensorEvent ev; cursor.next(ev);) {
    if (ev.kind == SensorEvent::Kind::kImu) {
      est.addImu(ev.t_s, log.imu[ev.index].imu);
      continue;
    }
    if (ev.kind != SensorEvent::Kind::kTdoa) continue;
    est.addTdoa(log.tdoa[ev.index]);
    if (after_tdoa) after_tdoa(ev.t_s);
    if (ev.t_s < t0_s || !est.ready()) continue;
    s += (est.state().w_p_b - circle(ev.t_s).p).squaredNorm();
    ++n;
  }
  return std::sqrt(s / std::max(n, 1));
}

/// β̂ of anchor `id` less the mean of the arena's other seven (the common offset no TDoA sees, F27d).
double learnedBias(const AnchorRangeBias& b, int id) {
  double others = 0.0;
  for (int k = 0; k < 8; ++k)
    if (k != id) others += b.mean(k) / 7.0;
  return b.mean(id) - others;
}

TEST(EkfRangeBias, LearnsAnAnchorRangeBiasThatMovedThePosition) {
  // GIVEN a circle flight whose anchor 3 reads every range 0.4 m long (pairs (2, 3) and (3, 4) carry ±0.4 m)
  const AnchorTable anchors = filtertest::arenaAnchors();
  constexpr double kBias_m = 0.4;
  const auto offset = [](double, int a) { return a == 2 ? kBias_m : (a == 3 ? -kBias_m : 0.0); };
  const SensorLog log = filtertest::flightLog(anchors, circle, 0.0, 60.0, 0.05, true, 11, offset);
  EkfParams off;
  off.ground_phase = GroundPhase::kNone;
  off.range_bias_sigma_m = 0.0;  // the filter without range-bias states
  off.tdoa_sigma_m = 0.35;
  EkfParams on = off;
  on.tdoa_sigma_m = 0.2;
  on.range_bias_sigma_m = 0.3;
  on.range_bias_tau_s = 1000.0;  // a constant bias
  // WHEN localizing without and with range-bias states
  Estimator est_off(off, anchors), est_on(on, anchors);
  const double e_off = runCircle(est_off, log, 30.0), e_on = runCircle(est_on, log, 30.0);
  // THEN the states find the anchor's bias (up to the common range offset that no TDoA sees) and its position error
  EXPECT_EQ(est_off.ekf().rangeBias(), nullptr);
  ASSERT_NE(est_on.ekf().rangeBias(), nullptr);
  EXPECT_NEAR(learnedBias(*est_on.ekf().rangeBias(), 3), kBias_m, 0.1);
  EXPECT_GT(e_off, 0.08);  // the bias does move the plain filter
  EXPECT_LT(e_on, 0.5 * e_off);
}

TEST(EkfRangeBias, TheAdaptedStdShrinksWithoutBiasAndGrowsBackWhenABiasAppears) {
  // GIVEN a circle flight without bias for 30 s, after which anchor 3 reads every range 0.15 m long
  const AnchorTable anchors = filtertest::arenaAnchors();
  constexpr double kBias_m = 0.15, kOnset_s = 30.0;
  const auto offset = [](double t, int a) {
    if (t < kOnset_s) return 0.0;
    return a == 2 ? kBias_m : (a == 3 ? -kBias_m : 0.0);
  };
  const SensorLog log = filtertest::flightLog(anchors, circle, 0.0, 70.0, 0.05, true, 12, offset);
  struct Run {
    double sigma_before = NAN, sigma_end = NAN, learned_m = NAN, rmse_end_m = NAN;
  };
  const auto run = [&](double adapt_s) {
    EkfParams p;
    p.ground_phase = GroundPhase::kNone;
    p.range_bias_adapt_s = adapt_s;  // the other range-bias parameters at their defaults
    Estimator est(p, anchors);
    Run r;
    r.rmse_end_m = runCircle(est, log, 60.0, [&](double t) {
      if (t < kOnset_s) r.sigma_before = est.ekf().rangeBias()->adaptedSigma();
    });
    const AnchorRangeBias& b = *est.ekf().rangeBias();
    r.learned_m = learnedBias(b, 3);
    r.sigma_end = b.adaptedSigma();
    return r;
  };
  // WHEN localizing with the defaults, the prior std fixed and adapted (F27e)
  const Run fixed = run(0.0), adapted = run(EkfParams{}.range_bias_adapt_s);
  // THEN without bias the adapted prior shrank (to its floor, 0.2 σ₀); once the bias appeared it grew back (the EM
  // fixed point: about the RMS of the anchors' biases), and the bias and the position are as with the fixed prior
  const double sigma0 = EkfParams{}.range_bias_sigma_m;
  EXPECT_DOUBLE_EQ(fixed.sigma_end, sigma0);
  EXPECT_LT(adapted.sigma_before, 0.5 * sigma0);
  EXPECT_GT(adapted.sigma_end, 2.0 * adapted.sigma_before);
  EXPECT_LE(adapted.sigma_end, sigma0);
  EXPECT_NEAR(adapted.learned_m, fixed.learned_m, 0.02);
  EXPECT_GT(adapted.learned_m, 0.03);
  EXPECT_LT(adapted.rmse_end_m, 1.05 * fixed.rmse_end_m);
}

TEST(EkfRangeBias, ABiasFreeFlightStaysAsGood) {
  // GIVEN the same flight without bias
  const AnchorTable anchors = filtertest::arenaAnchors();
  const SensorLog log = filtertest::flightLog(anchors, circle, 0.0, 40.0, 0.05, true, 12);
  EkfParams off;
  off.ground_phase = GroundPhase::kNone;
  off.range_bias_sigma_m = 0.0;
  off.tdoa_sigma_m = 0.35;
  const EkfParams on = [] {
    EkfParams p;  // the defaults: range-bias states on
    p.ground_phase = GroundPhase::kNone;
    return p;
  }();
  // WHEN localizing without and with range-bias states
  Estimator est_off(off, anchors), est_on(on, anchors);
  const double e_off = runCircle(est_off, log, 10.0), e_on = runCircle(est_on, log, 10.0);
  // THEN the states cost little accuracy (they only add freedom the TDoA do not ask for)
  EXPECT_LT(e_off, 0.05);
  EXPECT_LT(e_on, 0.05);
}

}  // namespace
}  // namespace uwb
