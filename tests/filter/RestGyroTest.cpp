/** @file RestGyroTest.cpp
 *  @brief The gyro bias read at rest (docs/math/filter.md F18z): the window statistics and the zero-angular-rate
 *         update of the EKF against a plain Kalman update and a finite-difference row. The estimator on a simulated
 *         flight: tests/regression/GyroBiasTest.cpp.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "uwb/filter/Ekf.h"
#include "uwb/filter/QuadImuProcess.h"
#include "uwb/filter/RestGyroWindow.h"

namespace uwb {
namespace {

TEST(RestGyroWindow, AFullWindowGivesTheMeanAndTheVarianceOfTheMean) {
  // GIVEN a 0.1 s window and readings at 100 Hz alternating about a bias
  RestGyroWindow w(0.1, 5);
  const Vec3 bias(0.01, -0.02, 0.013);
  std::optional<GyroWindowStats> out;
  int k = 0;
  // WHEN readings are added until the window is full (its first at t = 0, full at t = 0.1 s: 11 readings)
  for (; k <= 10 && !out; ++k) out = w.add(0.01 * k, bias + Vec3::Constant(k % 2 == 0 ? 0.001 : -0.001));
  // THEN the eleventh reading closes it: mean and sample variance / n of the 11 readings
  ASSERT_TRUE(out);
  EXPECT_EQ(out->n, 11);
  const Vec3 mean = bias + Vec3::Constant(0.001 / 11.0);  // six +0.001, five −0.001
  EXPECT_LT((out->mean_radps - mean).norm(), 1e-15);
  double ss = 0.0;
  for (int i = 0; i < 11; ++i) ss += std::pow((i % 2 == 0 ? 0.001 : -0.001) - 0.001 / 11.0, 2);
  EXPECT_NEAR(out->mean_var_radps2.x(), ss / 10.0 / 11.0, 1e-20);
  // AND the next window starts empty
  EXPECT_FALSE(w.add(0.12, bias));
}

TEST(RestGyroWindow, TooFewReadingsSayNothingAndClearForgets) {
  RestGyroWindow w(0.1, 5);
  // a 10 Hz gyro gives two readings per window: no statistics
  EXPECT_FALSE(w.add(0.0, Vec3::Zero()));
  EXPECT_FALSE(w.add(0.1, Vec3::Zero()));
  // a window cleared in the middle starts again at the next reading
  for (int k = 0; k < 5; ++k) EXPECT_FALSE(w.add(0.2 + 0.01 * k, Vec3::Ones()));
  w.clear();
  for (int k = 0; k < 10; ++k) EXPECT_FALSE(w.add(0.3 + 0.01 * k, Vec3::Zero()));
  const std::optional<GyroWindowStats> s = w.add(0.4, Vec3::Zero());
  ASSERT_TRUE(s);
  EXPECT_EQ(s->mean_radps, Vec3::Zero());
  EXPECT_THROW(RestGyroWindow(0.0, 5), std::invalid_argument);
  EXPECT_THROW(RestGyroWindow(0.1, 1), std::invalid_argument);
}

TEST(ZeroAngularRate, TheRowIsTheBiasComponentByFiniteDifferences) {
  // h(x) = b_g: ∂h_i/∂δx by central differences through x ⊞ δx equals the unit row at kGyroBias + i
  NavState x;
  x.b_gyro_bias = Vec3(0.01, -0.02, 0.03);
  x.w_q_b = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < kDim; ++j) {
      ErrVec d = ErrVec::Zero();
      d(j) = h;
      const double fd = (boxPlus(x, d).b_gyro_bias(i) - boxPlus(x, -d).b_gyro_bias(i)) / (2 * h);
      EXPECT_NEAR(fd, j == kGyroBias + i ? 1.0 : 0.0, 1e-9) << i << " " << j;
    }
  }
}

TEST(ZeroAngularRate, AConsistentReadingIsThePlainKalmanUpdate) {
  // GIVEN the filter's initial covariance and a bias reading within the gate
  EkfParams p;
  Ekf ekf(p);
  NavState x0;
  const ErrMat P0 = initialCovariance(p);
  ekf.initialize(x0, P0);
  const Vec3 reading(0.002, -0.001, 0.0005), var = Vec3::Constant(1e-6);
  // WHEN fused
  EXPECT_EQ(ekf.zeroAngularRateUpdate(reading, var, 4.0), 0);
  // THEN state and covariance are those of three sequential scalar Kalman updates on b_g
  ErrMat P = P0;
  ErrVec dx = ErrVec::Zero();
  for (int i = 0; i < 3; ++i) {
    const int k = kGyroBias + i;
    const double S = P(k, k) + var(i);
    const ErrVec K = P.col(k) / S;
    dx += K * (reading(i) - dx(k));
    P -= K * S * K.transpose();
  }
  EXPECT_LT((ekf.state().b_gyro_bias - dx.segment<3>(kGyroBias)).norm(), 1e-12);
  EXPECT_LT((ekf.covariance() - P).norm(), 1e-15);
}

TEST(ZeroAngularRate, AReadingBeyondChanceWidensTheBiasAndIsLearned) {
  // GIVEN the default yaw-axis bias std (0.001 rad/s) and a gyro whose z bias is 0.75°/s (the simulator's turn-on
  // bias is 0.5°/s per axis)
  EkfParams p;
  Ekf ekf(p);
  ekf.initialize(NavState{}, initialCovariance(p));
  const Vec3 bias(0.0, 0.0, 0.013);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 3e-4);
  // WHEN ten windows read it
  int widened = 0;
  for (int k = 0; k < 10; ++k)
    widened += ekf.zeroAngularRateUpdate(bias + Vec3(noise(rng), noise(rng), noise(rng)), Vec3::Constant(9e-8), 4.0);
  // THEN the first reading widened the z variance (13σ of the start's std), and the bias is known to its noise
  EXPECT_GE(widened, 1);
  EXPECT_NEAR(ekf.state().b_gyro_bias.z(), 0.013, 4e-4);
  EXPECT_LT(std::sqrt(ekf.covariance()(kGyroBias + 2, kGyroBias + 2)), 3e-4);
}

}  // namespace
}  // namespace uwb
