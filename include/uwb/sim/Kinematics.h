/** @file Kinematics.h
 *  @brief Quadrotor kinematics from flat outputs (differential flatness): attitude from the thrust direction,
 *  body rates from the attitude derivative, specific force in the body frame. docs/math/simulation.md (S7)–(S10).
 */
#pragma once

#include "uwb/core/Types.h"
#include "uwb/sim/Trajectory.h"

namespace uwb::sim {

/// Attitude w_q_b whose body z axis is parallel to the thrust w_a + g e_z and whose heading is yaw (S7, S8).
/// Requires |w_a + g e_z| > 0 (a quadrotor cannot fall freely while controlled); throws otherwise.
Quat attitudeFromAcceleration(const Vec3& w_a, double yaw_rad);

/// Full kinematic state of the body at one instant.
struct KinematicState {
  Vec3 w_p = Vec3::Zero();               ///< body origin [m]
  Vec3 w_v = Vec3::Zero();               ///< [m/s]
  Vec3 w_a = Vec3::Zero();               ///< [m/s²]
  Quat w_q_b = Quat::Identity();         ///< body → world
  Vec3 b_omega = Vec3::Zero();           ///< body rates [rad/s] (S9)
  Vec3 b_specific_force = Vec3::Zero();  ///< accelerometer truth R^T (a + g e_z) [m/s²] (S10)
  bool on_ground = false;
};

/// Evaluates the trajectory and derives attitude, body rates and specific force at t_s, for a vehicle with rotor drag
/// drag_per_s (S7′): its thrust is parallel to a + g e_z + k v_h.
KinematicState kinematicState(const Trajectory& trajectory, double t_s, double drag_per_s = 0.0);

}  // namespace uwb::sim
