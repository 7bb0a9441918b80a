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

}  // namespace uwb
