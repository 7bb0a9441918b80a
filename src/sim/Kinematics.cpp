/** @file Kinematics.cpp
 *  @brief Differential flatness of the quadrotor (Mellinger & Kumar 2011): docs/math/simulation.md (S7)–(S10).
 */
#include "uwb/sim/Kinematics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace uwb::sim {

Quat attitudeFromAcceleration(const Vec3& w_a, double yaw_rad) {
  // (S7) the thrust, hence the body z axis, is parallel to a + g e_z.
  const Vec3 w_thrust = w_a + Vec3(0.0, 0.0, kGravity_mps2);
  const double n = w_thrust.norm();
  if (!(n > 1e-6)) throw std::invalid_argument("attitudeFromAcceleration: free fall (|a + g e_z| = 0)");
  const Vec3 z_b = w_thrust / n;
  // (S8) heading: x_c = (cos ψ, sin ψ, 0), y_b = z_b × x_c / |·|, x_b = y_b × z_b.
  const Vec3 x_c(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  Vec3 y_b = z_b.cross(x_c);
  const double ny = y_b.norm();
  if (!(ny > 1e-6)) throw std::invalid_argument("attitudeFromAcceleration: thrust is horizontal");
  y_b /= ny;
  const Vec3 x_b = y_b.cross(z_b);
  Mat3 w_R_b;
  w_R_b.col(0) = x_b;
  w_R_b.col(1) = y_b;
  w_R_b.col(2) = z_b;
  Quat q(w_R_b);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() *= -1.0;  // canonical sign, so the pose stream has no sign flips
  return q;
}

namespace {
/// (S7′) the acceleration the thrust alone gives: a + k v_h (the drag −k v_h is the rest)
Vec3 thrustAcceleration(const FlatState& flat, double drag_per_s) {
  Vec3 a = flat.w_a;
  a.head<2>() += drag_per_s * flat.w_v.head<2>();
  return a;
}
}  // namespace

KinematicState kinematicState(const Trajectory& trajectory, double t_s, double drag_per_s) {
  const FlatState flat = trajectory.evaluate(t_s);
  KinematicState out;
  out.w_p = flat.w_p;
  out.w_v = flat.w_v;
  out.w_a = flat.w_a;
  out.on_ground = flat.on_ground;
  out.w_q_b = attitudeFromAcceleration(thrustAcceleration(flat, drag_per_s), flat.yaw_rad);
  // (S9) body rates ω = vee(Rᵀ Ṙ), evaluated as Log(R(t−h)ᵀ R(t+h)) / 2h: O(h²) accurate; the attitude is C1
  // (a is C1 because the trajectory is C3), so the rates are continuous.
  constexpr double h = 1e-4;
  const FlatState before = trajectory.evaluate(t_s - h);
  const FlatState after = trajectory.evaluate(t_s + h);
  const Quat q0 = attitudeFromAcceleration(thrustAcceleration(before, drag_per_s), before.yaw_rad);
  const Quat q1 = attitudeFromAcceleration(thrustAcceleration(after, drag_per_s), after.yaw_rad);
  const double span = std::min(t_s + h, trajectory.duration_s()) - std::max(t_s - h, 0.0);
  if (span > 0.0) {
    const Eigen::AngleAxisd rel(q0.conjugate() * q1);
    out.b_omega = rel.axis() * rel.angle() / span;
  }
  // (S10) accelerometer truth: specific force in the body frame (with drag its x/y read −k Rᵀ v_h, S7′).
  out.b_specific_force = out.w_q_b.conjugate() * (flat.w_a + Vec3(0.0, 0.0, kGravity_mps2));
  return out;
}

}  // namespace uwb::sim
