/** @file TrajectoryTest.cpp
 *  @brief Reference flights: analytic derivatives vs central differences, smooth joins, ground phases.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "support/DerivativeChecker.h"
#include "uwb/sim/Trajectory.h"

namespace uwb::sim {
namespace {

TrajectoryParams shortFlight(TrajectoryShape shape) {
  TrajectoryParams p;
  p.shape = shape;
  p.duration_s = 40.0;
  return p;
}

class EveryShape : public ::testing::TestWithParam<TrajectoryShape> {};

TEST_P(EveryShape, VelocityAndAccelerationMatchCentralDifferences) {
  // GIVEN a flight of each shape
  const Trajectory traj(shortFlight(GetParam()));
  SCOPED_TRACE(toString(GetParam()));
  const test::DifferenceOptions step{1e-4};  // the time offset δ is differentiated at 0: steps of ±0.1 ms
  // WHEN we sample it densely, including the phase joins
  for (double t = 0.0; t <= traj.duration_s(); t += 0.0137) {
    const FlatState s = traj.evaluate(t);
    // THEN the analytic derivatives agree with the numerical ones
    if (t > step.h && t < traj.duration_s() - step.h) {
      const auto p_at = [&](const VecX& d) { return VecX(traj.evaluate(t + d[0]).w_p); };
      const auto v_at = [&](const VecX& d) { return VecX(traj.evaluate(t + d[0]).w_v); };
      const test::JacobianCheck c_v = test::checkJacobian(p_at, VecX::Zero(1), s.w_v, step);
      const test::JacobianCheck c_a = test::checkJacobian(v_at, VecX::Zero(1), s.w_a, step);
      EXPECT_LT(c_v.max_abs_error, 1e-6) << "t = " << t << ": " << c_v;
      EXPECT_LT(c_a.max_abs_error, 1e-5) << "t = " << t << ": " << c_a;
    }
    EXPECT_LT(s.w_a.norm(), 0.5 * kGravity_mps2) << "t = " << t;  // a real quadrotor manoeuvre
  }
}

TEST_P(EveryShape, StartsAndEndsAtRestOnTheGround) {
  // GIVEN a flight
  const TrajectoryParams p = shortFlight(GetParam());
  const Trajectory traj(p);
  // WHEN we look at the first and the last seconds
  for (double t : {0.0, 1.0, p.ground_before_s - 0.01, p.duration_s - p.ground_after_s + 0.01, p.duration_s}) {
    const FlatState s = traj.evaluate(t);
    // THEN the drone sits on the ground, at rest
    EXPECT_TRUE(s.on_ground) << t;
    EXPECT_NEAR(s.w_p.z(), p.ground_z_m, 1e-12) << t;
    EXPECT_LT(s.w_v.norm(), 1e-12) << t;
    EXPECT_LT(s.w_a.norm(), 1e-12) << t;
  }
  // AND it flies in between
  EXPECT_GT(traj.evaluate(0.5 * p.duration_s).w_p.z(), 0.7);
}

TEST_P(EveryShape, AccelerationIsContinuousAcrossPhaseJoins) {
  // GIVEN the instants where one phase hands over to the next
  const TrajectoryParams p = shortFlight(GetParam());
  const Trajectory traj(p);
  const double t1 = p.ground_before_s + p.takeoff_s;
  const double joins[] = {p.ground_before_s, t1, t1 + p.speed_ramp_s, t1 + p.patternDuration_s() - p.speed_ramp_s,
                          t1 + p.patternDuration_s(), t1 + p.patternDuration_s() + p.landing_s};
  for (double tj : joins) {
    // WHEN we step across each join
    const double eps = 1e-7;
    const FlatState a = traj.evaluate(tj - eps);
    const FlatState b = traj.evaluate(tj + eps);
    // THEN position, velocity and acceleration do not jump (C2; the design is C3)
    EXPECT_LT((a.w_p - b.w_p).norm(), 1e-6) << tj;
    EXPECT_LT((a.w_v - b.w_v).norm(), 1e-5) << tj;
    EXPECT_LT((a.w_a - b.w_a).norm(), 1e-4) << tj;
  }
}

INSTANTIATE_TEST_SUITE_P(Shapes, EveryShape,
                         ::testing::Values(TrajectoryShape::kZigzag, TrajectoryShape::kCircle,
                                           TrajectoryShape::kCircleSine, TrajectoryShape::kFigureEight));

TEST(Trajectory, CircleHasTheCommandedRadiusHeightAndRate) {
  // GIVEN the util-pilot circle (r = 1.5 m, z = 1.5 m, ω = 0.6 rad/s) about (0.3, −0.2)
  TrajectoryParams p = shortFlight(TrajectoryShape::kCircle);
  p.w_center_xy = Vec2(0.3, -0.2);
  const Trajectory traj(p);
  // WHEN we sample the middle of the pattern (past the speed ramp)
  const double t = p.ground_before_s + p.takeoff_s + 10.0;
  const FlatState s = traj.evaluate(t);
  // THEN it lies on the circle with speed r ω and centripetal acceleration r ω²
  EXPECT_NEAR((s.w_p.head<2>() - p.w_center_xy).norm(), 1.5, 1e-9);
  EXPECT_NEAR(s.w_p.z(), 1.5, 1e-9);
  EXPECT_NEAR(s.w_v.norm(), 0.9, 1e-9);
  EXPECT_NEAR(s.w_a.norm(), 1.5 * 0.36, 1e-9);
}

TEST(Trajectory, YawRotatesAtTheConfiguredRateOrStaysConstant) {
  // GIVEN the same circle with a yaw rate and with constant yaw
  TrajectoryParams p = shortFlight(TrajectoryShape::kCircle);
  p.yaw_rate_rps = 0.5;
  const Trajectory rotating(p);
  p.yaw_mode = YawMode::kConstant;
  p.yaw0_rad = 0.3;
  const Trajectory fixed(p);
  // WHEN we difference the yaw in the middle of the pattern
  const double t = p.ground_before_s + p.takeoff_s + 10.0;
  const double rate = (rotating.evaluate(t + 0.01).yaw_rad - rotating.evaluate(t - 0.01).yaw_rad) / 0.02;
  // THEN it turns at 0.5 rad/s, or not at all
  EXPECT_NEAR(rate, 0.5, 1e-9);
  EXPECT_DOUBLE_EQ(fixed.evaluate(t).yaw_rad, 0.3);
  EXPECT_DOUBLE_EQ(fixed.evaluate(0.0).yaw_rad, 0.3);
}

TEST(Trajectory, RejectsADurationTooShortForTheGroundAndRampPhases) {
  TrajectoryParams p;
  p.duration_s = 10.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  EXPECT_THROW(Trajectory{p}, std::invalid_argument);
}

TEST(Trajectory, AFloorAboveTheZigzagBandNamesTheFields) {
  // GIVEN a floor (a start from a box) above the zigzag's lowest height THEN the error names the fields and values
  TrajectoryParams p;
  p.ground_z_m = 0.8;
  try {
    p.validate();
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("ground_z_m < zigzag_z_min_m"), std::string::npos) << what;
    EXPECT_NE(what.find("0.800000"), std::string::npos) << what;
  }
}

TEST(Trajectory, ParsesShapeNames) {
  for (const char* name : {"zigzag", "circle", "circle-sine", "figure8"}) {
    EXPECT_EQ(toString(parseTrajectoryShape(name)), name);
  }
  EXPECT_THROW(parseTrajectoryShape("spiral"), std::invalid_argument);
}

TEST(Smoothstep7, HasVanishingDerivativesAtBothEnds) {
  double d1 = 1.0, d2 = 1.0;
  EXPECT_DOUBLE_EQ(smoothstep7(0.0, &d1, &d2), 0.0);
  EXPECT_DOUBLE_EQ(d1, 0.0);
  EXPECT_DOUBLE_EQ(d2, 0.0);
  EXPECT_DOUBLE_EQ(smoothstep7(1.0, &d1, &d2), 1.0);
  EXPECT_NEAR(d1, 0.0, 1e-12);
  EXPECT_NEAR(d2, 0.0, 1e-12);
  for (double x : {0.1, 0.37, 0.5, 0.81}) {
    smoothstep7(x, &d1, &d2);
    const test::JacobianCheck c = test::checkGradient([](const VecX& v) { return smoothstep7(v[0]); },
                                                      VecX::Constant(1, x), VecX::Constant(1, d1));
    EXPECT_LT(c.max_abs_error, 1e-6) << c;
  }
}

}  // namespace
}  // namespace uwb::sim
