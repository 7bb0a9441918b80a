/** @file SimParams.h
 *  @brief Sensor rates, noise and bias magnitudes of the flight simulator (SI units; defaults Crazyflie-like).
 *
 *  IMU magnitudes: white noise per sample measured on util-pilot 0425-traj2 in flight (acc ≈ 0.006–0.024 g,
 *  gyro ≈ 0.16–0.29 deg/s per sample at ~1 kHz); turn-on biases of a BMI088-class MEMS IMU after the Crazyflie's
 *  start-up calibration. docs/math/simulation.md (S10), (S11), "Calibration".
 */
#pragma once

#include "uwb/core/Types.h"
#include "uwb/sim/SimulatedBias.h"

namespace uwb::sim {

/// Accelerometer and gyroscope: sample = truth + bias(t) + white noise; bias(0) ~ N(0, σ_b²) per axis,
/// then a random walk with density σ_rw (S11).
struct ImuParams {
  double rate_hz = 1000.0;
  double acc_noise_std_mps2 = 0.15;        ///< white noise per sample [m/s²]
  double acc_bias_std_mps2 = 0.10;         ///< turn-on bias per axis [m/s²]
  double acc_bias_rw_mps2_sqrt_s = 0.002;  ///< bias random walk [m/s² / √s]
  double gyro_noise_std_rps = 0.005;       ///< white noise per sample [rad/s] (≈ 0.29 deg/s)
  double gyro_bias_std_rps = 0.0087;       ///< turn-on bias per axis [rad/s] (≈ 0.5 deg/s)
  double gyro_bias_rw_rps_sqrt_s = 1e-4;   ///< bias random walk [rad/s / √s]
  /// White noise while the drone sits on the ground with the motors off (no rotor vibration): the Crazyflie's
  /// accelerometer then shows ≈ 0.003 g per sample (util-pilot, first second of every flight) [m/s²], [rad/s].
  double rest_acc_noise_std_mps2 = 0.03;
  double rest_gyro_noise_std_rps = 0.001;
  void validate() const;
};

/// Ground-truth pose stream (Vicon-like).
struct PoseParams {
  double rate_hz = 300.0;
  double position_quantum_m = 0.001;  ///< Vicon logs positions to 1 mm; 0 = no quantization
  double quat_quantum = 0.0;          ///< quaternion component quantization (util-pilot ≈ 0.0014); 0 = off
  void validate() const;
};

/// TDoA2 schedule: neighbour pairs (id_0,id_1), (id_1,id_2), …, (id_{n−1},id_0) in round robin (S19); or TDoA3:
/// each measurement a random pair of distinct anchors (S19b; util-pilot 0425-traj13: about 200 Hz).
struct TdoaScheduleParams {
  double rate_hz = 400.0;       ///< all pairs together (util-pilot: 370–430 Hz TDoA2, about 200 Hz TDoA3)
  double jitter_fraction = 0.3; ///< each interval is (1 + U(−j, j)) / rate
  bool tdoa3 = false;           ///< random pairs (TDoA3) instead of the neighbour round robin (TDoA2)
  void validate() const;
};

struct SimParams {
  ImuParams imu;
  PoseParams pose;
  TdoaScheduleParams tdoa;
  BiasParams bias;
  Vec3 b_t_tag = kUtilTagOffset_b;  ///< tag (antenna) lever arm in the body frame [m]
  /// Rotor drag per unit horizontal velocity, a = T z_b / m + g_w − k v_h (S7′) [1/s]: the thrust tilts further than
  /// the acceleration alone asks, and the accelerometer's x/y read −k Rᵀ v_h. Measured on the util-pilot 0426 flights
  /// against Vicon (0.33–0.39 /s; docs/math/simulation.md S7′).
  double rotor_drag_per_s = 0.36;
  bool write_full_util_header = true;  ///< Flight::columns = all 27 UTIL columns (tof/flow/baro left empty)

  /// Noise-free, bias-free sensors: for tests of kinematics and the measurement model.
  static SimParams noiseFree();
  /// Throws std::invalid_argument naming the offending field.
  void validate() const;
};

}  // namespace uwb::sim
