/** @file KinematicsTest.cpp
 *  @brief Flatness kinematics: the simulated IMU agrees with finite differences of the simulated pose.
 */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Kinematics.h"

namespace uwb::sim {
namespace {

SimResult noiseFreeFlight(TrajectoryShape shape) {
  Scenario sc = makeScenario(paperAnchors(), shape, 40.0);
  return simulateFlight(sc, SimParams::noiseFree(), 3);
}

TEST(Kinematics, BodyZAxisIsParallelToThrustAndHeadingFollowsYaw) {
  // GIVEN an acceleration and a yaw
  const Vec3 w_a(1.2, -0.7, 0.4);
  const double yaw = 0.8;
  // WHEN we compute the attitude
  const Quat q = attitudeFromAcceleration(w_a, yaw);
  const Mat3 R = q.toRotationMatrix();
  // THEN z_b ∥ a + g e_z, and y_b ⊥ x_c = (cos ψ, sin ψ, 0) (S8): x_b lies in the plane of x_c and z_b
  const Vec3 thrust = (w_a + Vec3(0, 0, kGravity_mps2)).normalized();
  EXPECT_LT((R.col(2) - thrust).norm(), 1e-12);
  const Vec3 x_c(std::cos(yaw), std::sin(yaw), 0.0);
  EXPECT_NEAR(R.col(1).dot(x_c), 0.0, 1e-12);
  EXPECT_GT(R.col(0).dot(x_c), 0.0);
  // AND for level flight the heading is exactly ψ
  const Mat3 level = attitudeFromAcceleration(Vec3::Zero(), yaw).toRotationMatrix();
  EXPECT_NEAR(std::atan2(level(1, 0), level(0, 0)), yaw, 1e-12);
  EXPECT_NEAR(q.norm(), 1.0, 1e-12);
}

TEST(Kinematics, SpecificForceAtRestIsOneGUp) {
  Trajectory traj(TrajectoryParams{});
  const KinematicState s = kinematicState(traj, 0.5);
  EXPECT_LT((s.b_specific_force - Vec3(0, 0, kGravity_mps2)).norm(), 1e-12);
  EXPECT_LT(s.b_omega.norm(), 1e-9);
}

TEST(Kinematics, RotorDragTiltsTheThrustAndShowsOnTheAccelerometersXY) {
  // GIVEN a vehicle with rotor drag k in flight on the default trajectory
  const Trajectory traj(TrajectoryParams{});
  const double k = 0.36;
  int moving = 0;
  for (double t = 8.0; t < 30.0; t += 0.37) {
    const KinematicState s = kinematicState(traj, t, k);
    const KinematicState s0 = kinematicState(traj, t);
    const Mat3 R = s.w_q_b.toRotationMatrix();
    const Vec3 v_h(s.w_v.x(), s.w_v.y(), 0.0);
    if (v_h.norm() > 0.3) ++moving;
    // THEN the thrust axis is parallel to a + g e_z + k v_h (S7′), the specific force is still Rᵀ (a + g e_z) (S10),
    // and what the thrust does not give, −k Rᵀ v_h, is what the accelerometer's x/y read
    const Vec3 thrust = (s.w_a + Vec3(0.0, 0.0, kGravity_mps2) + k * v_h).normalized();
    EXPECT_LT((R.col(2) - thrust).norm(), 1e-12) << t;
    EXPECT_LT((s.b_specific_force - R.transpose() * (s.w_a + Vec3(0.0, 0.0, kGravity_mps2))).norm(), 1e-12) << t;
    const Vec3 thrust_only = s.b_specific_force + k * (R.transpose() * v_h);
    EXPECT_LT(thrust_only.head<2>().norm(), 1e-12) << t;
    // AND the position and velocity are the trajectory's, with or without drag
    EXPECT_LT((s.w_p - s0.w_p).norm(), 1e-15);
  }
  EXPECT_GT(moving, 10);
}

class EveryShapeImu : public ::testing::TestWithParam<TrajectoryShape> {};

TEST_P(EveryShapeImu, AccelerometerEqualsSecondDifferenceOfPoseRotatedIntoBody) {
  // GIVEN a noise-free flight (pose 300 Hz, IMU 1 kHz: common instants every 10 ms)
  const SimResult r = noiseFreeFlight(GetParam());
  const auto& pose = r.pose_exact;
  const double dt = pose[1].t_s - pose[0].t_s;
  double worst = 0.0;
  for (std::size_t k = 3; k + 3 < pose.size(); k += 3) {
    // WHEN we difference the true position twice and rotate a + g e_z into the body frame
    const Vec3 w_a = (pose[k + 1].w_p_b - 2.0 * pose[k].w_p_b + pose[k - 1].w_p_b) / (dt * dt);
    const Vec3 expected = pose[k].w_q_b.conjugate() * (w_a + Vec3(0, 0, kGravity_mps2));
    const std::size_t i = k / 3 * 10;  // IMU index at the same instant
    ASSERT_NEAR(r.flight.acc[i].t_s, pose[k].t_s, 1e-9);
    // THEN the accelerometer sample matches (S10)
    worst = std::max(worst, (r.flight.acc[i].b_value - expected).norm());
  }
  EXPECT_LT(worst, 2e-3) << toString(GetParam());
}

TEST_P(EveryShapeImu, GyroscopeEqualsAttitudeDerivative) {
  // GIVEN a noise-free flight
  const SimResult r = noiseFreeFlight(GetParam());
  const auto& pose = r.pose_exact;
  const double dt = pose[1].t_s - pose[0].t_s;
  double worst = 0.0;
  double largest_rate = 0.0;
  for (std::size_t k = 3; k + 3 < pose.size(); k += 3) {
    // WHEN we take ω = Log(q_{k−1}⁻¹ q_{k+1}) / 2Δt from the true attitude
    const Eigen::AngleAxisd rel(pose[k - 1].w_q_b.conjugate() * pose[k + 1].w_q_b);
    const Vec3 expected = rel.axis() * rel.angle() / (2.0 * dt);
    const std::size_t i = k / 3 * 10;
    // THEN the gyroscope sample matches (S9)
    worst = std::max(worst, (r.flight.gyro[i].b_value - expected).norm());
    largest_rate = std::max(largest_rate, expected.norm());
  }
  EXPECT_LT(worst, 2e-3) << toString(GetParam());
  EXPECT_GT(largest_rate, 0.05);  // the test would be empty if nothing rotated
}

INSTANTIATE_TEST_SUITE_P(Shapes, EveryShapeImu,
                         ::testing::Values(TrajectoryShape::kZigzag, TrajectoryShape::kCircle,
                                           TrajectoryShape::kCircleSine, TrajectoryShape::kFigureEight));

TEST(Kinematics, ImuNoiseAndBiasHaveTheConfiguredMagnitudes) {
  // GIVEN a default flight (noise and bias on)
  Scenario sc = makeScenario(paperAnchors(), TrajectoryShape::kCircle, 60.0);
  const SimResult r = simulateFlight(sc, SimParams{}, 11);
  const ImuParams ip;
  // WHEN we subtract truth and bias from the samples
  // (flying and on the ground with the motors off separately: S10)
  const Trajectory traj(sc.trajectory);
  Vec3 sum_acc = Vec3::Zero(), sum_sq_acc = Vec3::Zero(), sum_sq_gyro = Vec3::Zero();
  Vec3 sum_sq_acc_rest = Vec3::Zero(), sum_sq_gyro_rest = Vec3::Zero();
  double n = 0.0, n_rest = 0.0;
  for (std::size_t i = 0; i < r.flight.acc.size(); ++i) {
    const ImuTruth& t = r.imu_truth[i];
    const Vec3 na = r.flight.acc[i].b_value - t.b_specific_force - t.b_acc_bias;
    const Vec3 ng = r.flight.gyro[i].b_value - t.b_omega - t.b_gyro_bias;
    if (traj.evaluate(r.flight.acc[i].t_s).on_ground) {
      sum_sq_acc_rest += na.cwiseProduct(na);
      sum_sq_gyro_rest += ng.cwiseProduct(ng);
      n_rest += 1.0;
      continue;
    }
    sum_acc += na;
    sum_sq_acc += na.cwiseProduct(na);
    sum_sq_gyro += ng.cwiseProduct(ng);
    n += 1.0;
  }
  ASSERT_GT(n_rest, 1000.0);
  // THEN the white noise has the configured standard deviation and zero mean, in flight and at rest
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(std::sqrt(sum_sq_acc[a] / n), ip.acc_noise_std_mps2, 0.02 * ip.acc_noise_std_mps2);
    EXPECT_NEAR(std::sqrt(sum_sq_gyro[a] / n), ip.gyro_noise_std_rps, 0.02 * ip.gyro_noise_std_rps);
    EXPECT_NEAR(sum_acc[a] / n, 0.0, 5.0 * ip.acc_noise_std_mps2 / std::sqrt(n));
    EXPECT_NEAR(std::sqrt(sum_sq_acc_rest[a] / n_rest), ip.rest_acc_noise_std_mps2, 0.05 * ip.rest_acc_noise_std_mps2);
    EXPECT_NEAR(std::sqrt(sum_sq_gyro_rest[a] / n_rest), ip.rest_gyro_noise_std_rps, 0.05 * ip.rest_gyro_noise_std_rps);
  }
  // AND the bias is non-zero and moves slowly
  EXPECT_GT(r.imu_truth.front().b_acc_bias.norm(), 0.0);
  EXPECT_LT((r.imu_truth.back().b_acc_bias - r.imu_truth.front().b_acc_bias).norm(), 0.1);
}

}  // namespace
}  // namespace uwb::sim
