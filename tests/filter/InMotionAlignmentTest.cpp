/** @file InMotionAlignmentTest.cpp
 *  @brief The in-motion alignment (docs/math/filter.md F28): a moving body's attitude from exact IMU samples and
 *         velocities, at any heading; no heading without horizontal velocity changes.
 */
#include "uwb/filter/InMotionAlignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "uwb/filter/QuadImuProcess.h"

namespace uwb {
namespace {

/// A tilted, yawing body on a circle: attitude R(t) = Rz(ψ₀ + ψ̇t) Ry(θ(t)) Rx(φ(t)), velocity of a circle.
struct Motion {
  double psi0 = 0.0, psi_rate = 0.5, radius = 1.5, omega = 0.7;
  Quat attitude(double t) const {
    return Quat(Eigen::AngleAxisd(psi0 + psi_rate * t, Vec3::UnitZ()) *
                Eigen::AngleAxisd(0.08 * std::sin(1.3 * t), Vec3::UnitY()) *
                Eigen::AngleAxisd(0.06 * std::cos(0.9 * t), Vec3::UnitX()));
  }
  Vec3 velocity(double t) const {
    return radius * omega * Vec3(-std::sin(omega * t), std::cos(omega * t), 0.1 * std::cos(2.0 * t));
  }
  Vec3 acceleration(double t) const {
    return radius * omega * Vec3(-omega * std::cos(omega * t), -omega * std::sin(omega * t), -0.2 * std::sin(2.0 * t));
  }
};

/// Feeds `seconds` of exact 1 kHz samples of m from t0; returns the alignment.
InMotionAlignment feed(const Motion& m, double t0, double seconds, double vel_noise_mps = 0.0,
                       const Vec3& gyro_bias = Vec3::Zero(), const Vec3& acc_bias = Vec3::Zero()) {
  InMotionAlignment a(seconds);
  const double dt = 1e-3;
  std::uint32_t state = 12345u;
  const auto noise = [&state] {  // a deterministic uniform draw in [−1, 1]
    state = state * 1664525u + 1013904223u;
    return static_cast<double>(state) / 2147483648.0 - 1.0;
  };
  for (int k = 0; k * dt <= seconds + 1e-9; ++k) {
    const double t = t0 + k * dt;
    const Quat q = m.attitude(t);
    // the specific force and rate held over the sample before t (the estimator's convention): at its middle
    const double tm = t - 0.5 * dt;
    const Quat qm = m.attitude(tm);
    const Vec3 f = qm.conjugate() * (m.acceleration(tm) + Vec3(0.0, 0.0, kGravity_mps2));
    const Eigen::AngleAxisd step(m.attitude(t - dt).conjugate() * q);
    const Vec3 w = step.axis() * step.angle() / dt;
    Vec3 v = m.velocity(t);
    if (vel_noise_mps > 0.0) v += vel_noise_mps * Vec3(noise(), noise(), noise());
    a.add(t, f + acc_bias, w + gyro_bias, k == 0 ? 0.0 : dt, v);
  }
  return a;
}

/// Feeds `seconds` of 1 kHz samples of a vehicle with rotor drag k flying the circle of m (F28a′): its thrust is
/// parallel to a + g e_z + k v_h (heading psi0 + psi_rate t), and the estimator's sample is the thrust-axis reading.
/// The alignment is told drag model_drag_per_s.
InMotionAlignment feedWithDrag(const Motion& m, double drag_per_s, double model_drag_per_s, double seconds) {
  InMotionAlignment a(seconds, InMotionAlignment::kDefaultSamplePeriod_s, InMotionAlignment::kDefaultCorrelation_s,
                      model_drag_per_s);
  const auto attitude = [&](double t) {
    Vec3 thrust = m.acceleration(t) + Vec3(0.0, 0.0, kGravity_mps2);
    thrust.head<2>() += drag_per_s * m.velocity(t).head<2>();
    const Vec3 z_b = thrust.normalized();
    const double psi = m.psi0 + m.psi_rate * t;
    const Vec3 y_b = z_b.cross(Vec3(std::cos(psi), std::sin(psi), 0.0)).normalized();
    Mat3 R;
    R << y_b.cross(z_b), y_b, z_b;
    return Quat(R);
  };
  const double dt = 1e-3;
  for (int k = 0; k * dt <= seconds + 1e-9; ++k) {
    const double t = k * dt, tm = t - 0.5 * dt;
    const Vec3 f_full = attitude(tm).conjugate() * (m.acceleration(tm) + Vec3(0.0, 0.0, kGravity_mps2));
    const Eigen::AngleAxisd step(attitude(t - dt).conjugate() * attitude(t));
    a.add(t, Vec3(0.0, 0.0, f_full.z()), step.axis() * step.angle() / dt, k == 0 ? 0.0 : dt, m.velocity(t));
  }
  return a;
}

TEST(InMotionAlignment, RotorDragInTheModelKeepsTheHeadingOfADraggedCircle) {
  // GIVEN a vehicle with the rotor drag measured on the util-pilot flights, on a circle at 1 m/s, heading 40°
  Motion m;
  m.psi0 = 0.7;
  m.psi_rate = 0.0;
  const double k = 0.36;
  // WHEN the alignment models the drag, THEN the heading is found to a fraction of a degree
  const std::optional<InMotionAlignment::Result> with = feedWithDrag(m, k, k, 8.0).solve();
  ASSERT_TRUE(with.has_value());
  EXPECT_NEAR(wrapAngle(headingOf(with->w_q_b) - m.psi0), 0.0, 0.5 * kDegToRad);
  // AND WHEN it leaves the drag out (the thrust-axis model alone), THEN the drag, at right angles to the centripetal
  // acceleration, turns the heading by degrees
  const std::optional<InMotionAlignment::Result> without = feedWithDrag(m, k, 0.0, 8.0).solve();
  ASSERT_TRUE(without.has_value());
  EXPECT_GT(std::abs(wrapAngle(headingOf(without->w_q_b) - m.psi0)), 5.0 * kDegToRad);
  // AND a negative drag is an error
  EXPECT_THROW(InMotionAlignment(8.0, 0.1, 1.0, -0.1), std::invalid_argument);
}

TEST(InMotionAlignment, FindsTheAttitudeAtAnyHeading) {
  for (double psi0 : {0.0, 1.0, 2.3, -2.9}) {
    Motion m;
    m.psi0 = psi0;
    // GIVEN 4 s of exact samples of a yawing, tilting body on a circle
    const InMotionAlignment a = feed(m, 3.0, 4.0);
    ASSERT_TRUE(a.complete());
    const auto r = a.solve();
    ASSERT_TRUE(r);
    // THEN the attitude at the window's end is the true one, whatever the heading
    const Quat truth = m.attitude(7.0);
    // (to the samples' own discretisation: the specific force at the middle of each 1 ms step)
    EXPECT_LT(r->w_q_b.angularDistance(truth), 4e-3) << "psi0 " << psi0;
    EXPECT_NEAR(wrapAngle(headingOf(r->w_q_b) - headingOf(truth)), 0.0, 4e-3);
    EXPECT_LT(r->rms_residual_mps, 2e-3);
    EXPECT_GT(r->horizontal_excitation_mps, 0.5);
  }
}

TEST(InMotionAlignment, AWindowEndingBetweenIntegrationStepsGivesTheAttitudeAtItsLastSample) {
  // GIVEN a window of 4.03 s: it completes 30 ms after its last stored increment and between two integration steps
  Motion m;
  m.psi_rate = 1.0;
  const InMotionAlignment a = feed(m, 3.0, 4.03);
  ASSERT_TRUE(a.complete());
  const auto r = a.solve();
  ASSERT_TRUE(r);
  // THEN the attitude is the one at the last sample (30 ms of yaw at 1 rad/s would be 0.03 rad)
  const Quat truth = m.attitude(7.03);
  EXPECT_LT(r->w_q_b.angularDistance(truth), 4e-3);
  EXPECT_NEAR(wrapAngle(headingOf(r->w_q_b) - headingOf(truth)), 0.0, 4e-3);
}

TEST(InMotionAlignment, BiasJacobiansMatchFiniteDifferences) {
  // GIVEN the same 3 s of samples with a bias subtracted, b and b + ε e_i
  Motion m;
  const double eps = 1e-6;
  const InMotionAlignment a0 = feed(m, 0.5, 3.0);
  for (int i = 0; i < 3; ++i) {
    const Vec3 e = Vec3::Unit(i) * eps;
    // subtracting ε from the samples is adding −ε: the samples fed carry −ε
    const InMotionAlignment ag = feed(m, 0.5, 3.0, 0.0, -e, Vec3::Zero());
    const InMotionAlignment aa = feed(m, 0.5, 3.0, 0.0, Vec3::Zero(), -e);
    const Vec3 dbeta_g = (ag.integratedSpecificForce() - a0.integratedSpecificForce()) / eps;
    const Vec3 dbeta_a = (aa.integratedSpecificForce() - a0.integratedSpecificForce()) / eps;
    const Eigen::AngleAxisd drot(a0.rotationSinceStart().conjugate() * ag.rotationSinceStart());
    const Vec3 dphi = drot.axis() * drot.angle() / eps;
    // THEN ∂β/∂b, Φ are the columns the differences give
    EXPECT_LT((dbeta_g - a0.gyroBiasJacobian().col(i)).norm(), 1e-3 * (1.0 + dbeta_g.norm())) << i;
    EXPECT_LT((dbeta_a - a0.accBiasJacobian().col(i)).norm(), 1e-4 * (1.0 + dbeta_a.norm())) << i;
    EXPECT_LT((dphi - a0.rotationGyroBiasJacobian().col(i)).norm(), 1e-3) << i;
  }
}

TEST(InMotionAlignment, BiasedSamplesStillGiveTheAttitude) {
  // GIVEN exact samples with a gyro bias (a tilt drift of 1.1° over the window) and an accelerometer bias
  Motion m;
  m.psi0 = -1.2;
  const Vec3 bg(0.002, -0.0015, 0.001), ba(0.05, -0.04, 0.08);
  const auto r = feed(m, 1.0, 8.0, 0.0, bg, ba).solve();
  ASSERT_TRUE(r);
  // THEN the attitude is found to within 0.35° (the biases themselves trade against each other and the samples'
  // discretisation at this level; their Jacobians are checked above), and the bias changes solved for point the
  // way of the biases
  EXPECT_LT(r->w_q_b.angularDistance(m.attitude(9.0)), 6e-3);
  EXPECT_GT(r->gyro_bias_change_radps.dot(bg), 0.0);
  EXPECT_GT(r->acc_bias_change_mps2.dot(ba), 0.0);
  EXPECT_LT(r->rms_residual_mps, 0.02);
}

TEST(InMotionAlignment, NoisyVelocitiesGiveAHeadingWithinItsSigmaWhichALongerWindowShrinks) {
  Motion m;
  m.psi0 = 2.0;
  // GIVEN velocities with 0.1 m/s of noise, over 4 s and over 8 s
  const auto r4 = feed(m, 0.0, 4.0, 0.1).solve();
  const auto r8 = feed(m, 0.0, 8.0, 0.1).solve();
  ASSERT_TRUE(r4 && r8);
  // THEN each heading is within 3σ of the truth, and the longer window knows it better
  for (const auto& [r, t_end] : {std::pair{*r4, 4.0}, std::pair{*r8, 8.0}}) {
    const double err = std::abs(wrapAngle(headingOf(r.w_q_b) - headingOf(m.attitude(t_end))));
    EXPECT_LT(err, 3.0 * r.heading_sigma_rad) << t_end;
    EXPECT_GT(r.rms_residual_mps, 0.02);
  }
  EXPECT_LT(r8->heading_sigma_rad, 0.5 * r4->heading_sigma_rad);
  EXPECT_LT(r8->heading_sigma_rad, 0.2);
}

TEST(InMotionAlignment, WithoutHorizontalVelocityChangesTheHeadingIsUnknown) {
  // GIVEN a body at constant velocity (tilted, yawing): only gravity in the increments
  Motion m;
  m.radius = 0.0;
  const auto r = feed(m, 0.0, 4.0, 0.05).solve();
  ASSERT_TRUE(r);
  EXPECT_LT(r->horizontal_excitation_mps, 0.1);
  EXPECT_GT(r->heading_sigma_rad, 0.3);
}

TEST(InMotionAlignment, HeadingJacobianMatchesFiniteDifferences) {
  // GIVEN tilted attitudes at several headings
  for (const Vec3& rpy : {Vec3(0.0, 0.0, 0.4), Vec3(0.3, -0.2, 2.8), Vec3(-0.5, 0.4, -1.9)}) {
    const Quat q(Eigen::AngleAxisd(rpy.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Vec3::UnitY()) *
                 Eigen::AngleAxisd(rpy.x(), Vec3::UnitX()));
    const Eigen::RowVector3d J = headingJacobian(q);
    for (int i = 0; i < 3; ++i) {
      const double h = 1e-6;
      const double fd = wrapAngle(headingOf(q * expQuat(Vec3::Unit(i) * h)) - headingOf(q * expQuat(-Vec3::Unit(i) * h))) /
                        (2.0 * h);
      // THEN the analytic row is the central difference
      EXPECT_NEAR(J(i), fd, 1e-7) << rpy.transpose() << " axis " << i;
    }
  }
}

TEST(InMotionAlignment, TheLongestWindowFitsItsIncrementsAndALongerOneIsRejected) {
  // GIVEN the longest window the bounded memory holds, THEN exact samples over it give the attitude
  const Motion m;
  const InMotionAlignment a = feed(m, 0.0, InMotionAlignment::kMaxWindow_s);
  ASSERT_TRUE(a.complete());
  const std::optional<InMotionAlignment::Result> r = a.solve();
  ASSERT_TRUE(r.has_value());
  EXPECT_LT(r->rms_residual_mps, 1e-3);
  EXPECT_NEAR(wrapAngle(headingOf(r->w_q_b) - headingOf(m.attitude(InMotionAlignment::kMaxWindow_s))), 0.0, 4e-3);
  // WHEN the window is longer than the increments it could store, or not positive, THEN it is an error, not a window
  // that silently ends early
  EXPECT_THROW(InMotionAlignment(InMotionAlignment::kMaxWindow_s + 0.11), std::invalid_argument);
  EXPECT_THROW(InMotionAlignment(30.0), std::invalid_argument);
  EXPECT_THROW(InMotionAlignment(0.0), std::invalid_argument);
  EXPECT_THROW(InMotionAlignment(4.0, 0.0), std::invalid_argument);
}

TEST(InMotionAlignment, HeadingOfAndWrapAngle) {
  EXPECT_NEAR(headingOf(Quat(Eigen::AngleAxisd(2.5, Vec3::UnitZ()))), 2.5, 1e-12);
  EXPECT_NEAR(wrapAngle(3.0 * M_PI / 2.0), -M_PI / 2.0, 1e-12);
  EXPECT_NEAR(wrapAngle(-0.3), -0.3, 1e-12);
}

}  // namespace
}  // namespace uwb
