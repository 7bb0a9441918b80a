/** @file QuadImuProcessTest.cpp
 *  @brief The process model's analytic Jacobians F and G against central differences (docs/math/filter.md F4–F5).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "support/TestSupport.h"
#include "uwb/filter/Ekf.h"
#include "uwb/filter/QuadImuProcess.h"

namespace uwb {
namespace {

NavState randomState(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  NavState x;
  x.w_p_b = Vec3(n(rng), n(rng), 1.0 + n(rng));
  x.w_v_b = Vec3(n(rng), n(rng), 0.3 * n(rng));
  x.w_q_b = Quat(Eigen::AngleAxisd(0.3 * n(rng), Vec3(n(rng), n(rng), n(rng)).normalized())).normalized();
  x.b_acc_bias = 0.2 * Vec3(n(rng), n(rng), n(rng));
  x.b_gyro_bias = 0.02 * Vec3(n(rng), n(rng), n(rng));
  return x;
}

ImuReading randomImu(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  ImuReading imu;
  imu.b_acc_mps2 = Vec3(n(rng), n(rng), kGravity_mps2 + n(rng));
  imu.b_gyro_radps = Vec3(n(rng), n(rng), n(rng));
  return imu;
}

/// (accelerometer model, seed, rotor drag k [1/s]; F2a: the drag enters the thrust model only)
class QuadImuProcessJacobian : public ::testing::TestWithParam<std::tuple<AccelModel, int, double>> {};

TEST_P(QuadImuProcessJacobian, FMatchesCentralDifferences) {
  // GIVEN a random state, IMU reading and step
  // std::get, not a structured binding: lambdas below capture `model` (clang 14 rejects capturing a binding)
  const auto model = std::get<0>(GetParam());
  const auto seed = std::get<1>(GetParam());
  const double drag = std::get<2>(GetParam());
  SCOPED_TRACE("seed " + std::to_string(seed) + ", drag " + std::to_string(drag));
  std::mt19937 rng(seed);
  const NavState x = randomState(rng);
  const ImuReading imu = randomImu(rng);
  const double dt = 0.01;
  // WHEN we differentiate x' ⊟ f(x) with respect to the error state
  const ProcessStep ref = quadImuProcess(x, imu, dt, model, drag);
  const auto f = [&](const VecX& dx) -> VecX {
    const ErrVec d = dx;
    return boxMinus(quadImuProcess(boxPlus(x, d), imu, dt, model, drag).next, ref.next);
  };
  const test::JacobianCheck c = test::checkJacobian(f, VecX::Zero(kDim), ref.F());
  // THEN the analytic F agrees
  EXPECT_LT(c.max_abs_error, 1e-6) << c;
}

TEST_P(QuadImuProcessJacobian, GMatchesCentralDifferences) {
  // GIVEN a random state, reading and step
  // std::get, not a structured binding: lambdas below capture `model` (clang 14 rejects capturing a binding)
  const auto model = std::get<0>(GetParam());
  const auto seed = std::get<1>(GetParam());
  const double drag = std::get<2>(GetParam());
  std::mt19937 rng(seed + 100);
  const NavState x = randomState(rng);
  const ImuReading imu = randomImu(rng);
  const double dt = 0.01;
  const ProcessStep ref = quadImuProcess(x, imu, dt, model, drag);
  // WHEN we perturb the reading noise n_a, n_g and the bias increments
  const auto f = [&](const VecX& n) -> VecX {
    ImuReading m = imu;
    m.b_acc_mps2 += n.segment<3>(kNoiseAcc);
    m.b_gyro_radps += n.segment<3>(kNoiseGyro);
    NavState next = quadImuProcess(x, m, dt, model, drag).next;
    next.b_acc_bias += n.segment<3>(kNoiseAccBias);
    next.b_gyro_bias += n.segment<3>(kNoiseGyroBias);
    return boxMinus(next, ref.next);
  };
  const test::JacobianCheck c = test::checkJacobian(f, VecX::Zero(kNoiseDim), ref.G());
  // THEN the analytic G agrees
  EXPECT_LT(c.max_abs_error, 1e-6) << c;
}

INSTANTIATE_TEST_SUITE_P(BothAccelModels, QuadImuProcessJacobian,
                         ::testing::Combine(::testing::Values(AccelModel::kFull, AccelModel::kThrustOnly),
                                            ::testing::Values(1, 2, 3), ::testing::Values(0.0, 0.5)));

TEST(QuadImuProcess, RotorDragSlowsTheHorizontalVelocityOfTheThrustModelOnly) {
  // GIVEN a level body moving at 1 m/s along x, reading exactly gravity on its thrust axis
  NavState x;
  x.w_v_b = Vec3(1.0, 0.0, 0.0);
  ImuReading imu;
  // WHEN predicting one second in 1 ms steps with drag k = 0.5 /s (F2a)
  NavState thrust = x, full = x;
  for (int i = 0; i < 1000; ++i) {
    thrust = quadImuProcess(thrust, imu, 0.001, AccelModel::kThrustOnly, 0.5).next;
    full = quadImuProcess(full, imu, 0.001, AccelModel::kFull, 0.5).next;
  }
  // THEN the thrust model's velocity decays as exp(−k t) and its path as (1 − exp(−k t)) / k; the full model's x/y
  // readings carry the drag, so it adds none
  EXPECT_NEAR(thrust.w_v_b.x(), std::exp(-0.5), 1e-3);
  EXPECT_NEAR(thrust.w_p_b.x(), (1.0 - std::exp(-0.5)) / 0.5, 1e-3);
  EXPECT_NEAR(full.w_v_b.x(), 1.0, 1e-12);
  EXPECT_NEAR(thrust.w_v_b.z(), 0.0, 1e-12);
}

TEST(QuadImuProcess, HoverAtRestStaysPut) {
  // GIVEN a level body at rest reading exactly gravity
  NavState x;
  x.w_p_b = Vec3(1, 2, 1.5);
  ImuReading imu;
  // WHEN predicting one second in 1 ms steps
  for (int i = 0; i < 1000; ++i) x = quadImuProcess(x, imu, 0.001, AccelModel::kThrustOnly).next;
  // THEN nothing moves
  EXPECT_LT((x.w_p_b - Vec3(1, 2, 1.5)).norm(), 1e-9);
  EXPECT_LT(x.w_v_b.norm(), 1e-9);
}

TEST(QuadImuProcess, ZeroDtIsIdentity) {
  std::mt19937 rng(5);
  const NavState x = randomState(rng);
  const ProcessStep s = quadImuProcess(x, randomImu(rng), 0.0, AccelModel::kFull);
  EXPECT_LT(boxMinus(s.next, x).norm(), 1e-12);
  EXPECT_TRUE(s.F().isIdentity(1e-12));
}

TEST(AccumulatedTransition, BlockProductEqualsDenseProduct) {
  // GIVEN several random IMU steps
  std::mt19937 rng(11);
  NavState x = randomState(rng);
  AccumulatedTransition phi;
  ErrMat dense = ErrMat::Identity();
  for (int k = 0; k < 7; ++k) {
    // the thrust model with rotor drag on every other step (F2a: diagonal F_pv, F_vv)
    const ProcessStep s = k % 2 == 0 ? quadImuProcess(x, randomImu(rng), 0.003, AccelModel::kFull)
                                     : quadImuProcess(x, randomImu(rng), 0.05, AccelModel::kThrustOnly, 0.8);
    // WHEN accumulating in block form and densely
    phi.accumulate(s.J);
    dense = s.F() * dense;
    x = s.next;
  }
  // THEN both agree, and Φ M equals the block left-multiplication
  EXPECT_LT((phi.dense() - dense).cwiseAbs().maxCoeff(), 1e-12);
  const ErrMat M = ErrMat::Random();
  EXPECT_LT((phi.leftMultiply(M) - dense * M).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(TdoaOnlyPropagation, StructuredEqualsDenseStepByStep) {
  for (const ProcessModel model : {ProcessModel::kConstantVelocity, ProcessModel::kConstantAcceleration}) {
    // GIVEN a random SPD covariance and several TDoA-only prediction steps of different lengths
    EkfParams params;
    params.process_model = model;
    Ekf ekf(params);
    std::mt19937 rng(3);
    NavState x = randomState(rng);
    const ErrMat L = ErrMat::Random();
    const ErrMat P0 = L * L.transpose() + ErrMat::Identity();
    ekf.initialize(x, P0);
    ErrMat P_dense = ekf.covariance();
    const double q = model == ProcessModel::kConstantAcceleration
                         ? params.ca_jerk_noise_mps3_sqrthz * params.ca_jerk_noise_mps3_sqrthz
                         : params.cv_acc_noise_mps2_sqrthz * params.cv_acc_noise_mps2_sqrthz;
    for (const double dt : {0.0025, 0.004, 0.001, 0.0125}) {
      // WHEN predicting in the filter (pending T, structured fold) and densely per step (F9)
      ekf.predictTdoaOnly(dt);
      const ErrMat F = tdoaOnlyProcess(x, dt, model);
      ErrMat Q = ErrMat::Zero();
      for (int i = 0; i < 3; ++i) {
        if (model == ProcessModel::kConstantAcceleration) {
          Q(kPos + i, kPos + i) = q * std::pow(dt, 5) / 20.0;
          Q(kPos + i, kVel + i) = Q(kVel + i, kPos + i) = q * std::pow(dt, 4) / 8.0;
          Q(kPos + i, kAccBias + i) = Q(kAccBias + i, kPos + i) = q * std::pow(dt, 3) / 6.0;
          Q(kVel + i, kVel + i) = q * std::pow(dt, 3) / 3.0;
          Q(kVel + i, kAccBias + i) = Q(kAccBias + i, kVel + i) = q * dt * dt / 2.0;
          Q(kAccBias + i, kAccBias + i) = q * dt;
        } else {
          Q(kPos + i, kPos + i) = q * std::pow(dt, 3) / 3.0;
          Q(kPos + i, kVel + i) = Q(kVel + i, kPos + i) = q * dt * dt / 2.0;
          Q(kVel + i, kVel + i) = q * dt;
        }
      }
      P_dense = F * P_dense * F.transpose() + Q;
    }
    ekf.propagateCovariance();
    // THEN the covariance and the nominal state agree with the dense step-by-step propagation
    EXPECT_LT((ekf.covariance() - P_dense).cwiseAbs().maxCoeff(), 1e-12 * P_dense.cwiseAbs().maxCoeff());
    EXPECT_LT(boxMinus(ekf.state(), x).norm(), 1e-12);
    EXPECT_DOUBLE_EQ(ekf.pendingDt(), 0.0);
  }
}

TEST(ImuPropagation, BlockFoldEqualsDensePhiPPhiT) {
  // GIVEN a random SPD covariance and several IMU steps
  EkfParams params;
  Ekf ekf(params);
  std::mt19937 rng(17);
  NavState x = randomState(rng);
  const ErrMat L = ErrMat::Random();
  ekf.initialize(x, L * L.transpose() + ErrMat::Identity());
  const ErrMat P0 = ekf.covariance();
  AccumulatedTransition phi;
  for (int k = 0; k < 5; ++k) {
    const ImuReading imu = randomImu(rng);
    ekf.predict(imu, 0.002);
    phi.accumulate(quadImuProcess(x, imu, 0.002, params.accel_model, params.rotor_drag_per_s).J);
    x = quadImuProcess(x, imu, 0.002, params.accel_model, params.rotor_drag_per_s).next;
  }
  // WHEN folding Φ into P (F7)
  ekf.propagateCovariance();
  // THEN the result equals the dense Φ P Φᵀ up to the (diagonal) process noise and is symmetric
  const ErrMat dense = phi.dense() * P0 * phi.dense().transpose();
  ErrMat diff = ekf.covariance() - dense;
  diff.diagonal().setZero();
  EXPECT_LT(diff.cwiseAbs().maxCoeff(), 1e-12 * dense.cwiseAbs().maxCoeff());
  EXPECT_LT((ekf.covariance() - ekf.covariance().transpose()).cwiseAbs().maxCoeff(), 1e-12 * dense.cwiseAbs().maxCoeff());
  EXPECT_GE((ekf.covariance().diagonal() - dense.diagonal()).minCoeff(), -1e-12 * dense.cwiseAbs().maxCoeff());  // Q ≥ 0
}

TEST(So3, ExpLogRoundTripAndRightJacobian) {
  const Vec3 phi(0.3, -0.2, 0.5);
  EXPECT_LT((logQuat(expQuat(phi)) - phi).norm(), 1e-12);
  // Exp(φ + δ) ≈ Exp(φ) Exp(J_r δ)
  const auto f = [&](const VecX& d) -> VecX {
    return logQuat(expQuat(phi).conjugate() * expQuat(phi + Vec3(d)));
  };
  const test::JacobianCheck c = test::checkJacobian(f, VecX::Zero(3), rightJacobianSo3(phi));
  EXPECT_LT(c.max_abs_error, 1e-7) << c;
}

}  // namespace
}  // namespace uwb
