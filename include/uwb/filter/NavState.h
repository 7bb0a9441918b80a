/** @file NavState.h
 *  @brief Nominal state of the error-state Kalman filter and the IMU reading that drives it
 *         (docs/math/filter.md F1–F2).
 */
#pragma once

#include "uwb/core/Types.h"

namespace uwb {

/// Nominal navigation state (Mueller, Hamer, D'Andrea 2015, with bias states). SI units, world frame z up.
struct NavState {
  Vec3 w_p_b = Vec3::Zero();       ///< body origin in the world frame [m]
  Vec3 w_v_b = Vec3::Zero();       ///< body velocity in the world frame [m/s]
  Quat w_q_b = Quat::Identity();   ///< body→world rotation
  Vec3 b_acc_bias = Vec3::Zero();  ///< accelerometer bias, body frame [m/s²]
  Vec3 b_gyro_bias = Vec3::Zero(); ///< gyroscope bias, body frame [rad/s]
};

/// One IMU reading (or the mean of several): specific force and angular rate in the body frame.
struct ImuReading {
  Vec3 b_acc_mps2 = Vec3(0.0, 0.0, kGravity_mps2);  ///< specific force [m/s²] (≈ (0,0,g) at rest)
  Vec3 b_gyro_radps = Vec3::Zero();                ///< angular rate [rad/s]
};

/// (R(q) b_v)_z, the vertical part of a body-frame vector in the world frame, from the third row of R(q) alone
/// (R = I + 2w[u]× + 2[u]×², q = (w, u)): the IMU-rate paths need no full rotation.
inline double worldVertical(const Quat& w_q_b, const Vec3& b_v) {
  const Quat& q = w_q_b;
  return 2.0 * (q.x() * q.z() - q.w() * q.y()) * b_v.x() + 2.0 * (q.y() * q.z() + q.w() * q.x()) * b_v.y() +
         (1.0 - 2.0 * (q.x() * q.x() + q.y() * q.y())) * b_v.z();
}

}  // namespace uwb
