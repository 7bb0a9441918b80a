/** @file FilterTestUtil.h
 *  @brief Shared set-ups of the synthetic-flight filter tests: the UTIL-like anchor arena and a take-off profile.
 */
#pragma once

#include <functional>
#include <random>

#include "uwb/filter/SensorEvents.h"
#include "uwb/filter/TdoaUpdate.h"
#include "uwb/model/TdoaModel.h"

namespace uwb::filtertest {

/// 8 anchors alternating low/high on a 7 × 8 × 3 m box (as the UTIL arena).
inline AnchorTable arenaAnchors() {
  AnchorTable t;
  const Vec3 c[8] = {{-3, -4, 0.2}, {-3, 4, 3.0}, {3.5, 4, 0.2}, {4, -4, 3.0},
                     {-3, -4.2, 3.0}, {4, -3.8, 0.2}, {4, 4, 3.0}, {-3, 3.5, 0.2}};
  for (int i = 0; i < 8; ++i) t.set(i, c[i]);
  return t;
}

/// World position, velocity and acceleration of a level body at one instant.
struct Truth {
  Vec3 p, v, a;
};

/// Synthetic log over [t0_s, t1_s]: a level body following `truth(t)`; IMU at 1 kHz with rotor vibration (specific
/// force a + g e_z plus 0.5 m/s² white noise, gyro noise gyro_std_radps: a still IMU would mean "motors off"); TDoA
/// on the neighbour pairs of `anchors` (ids 0…7) at 400 Hz with white noise sigma_m; `tdoa_offset(t, pair)` adds a
/// deterministic error.
inline SensorLog flightLog(const AnchorTable& anchors, const std::function<Truth(double)>& truth, double t0_s,
                           double t1_s, double sigma_m, bool with_imu, unsigned seed,
                           const std::function<double(double, int)>& tdoa_offset = {},
                           double gyro_std_radps = 0.08) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  SensorLog log;
  if (with_imu) {
    for (double t = t0_s; t <= t1_s; t += 0.001) {
      TimedImu s;
      s.t_s = t;
      s.imu.b_acc_mps2 = truth(t).a + Vec3(0, 0, kGravity_mps2) + 0.5 * Vec3(n(rng), n(rng), n(rng));
      s.imu.b_gyro_radps = gyro_std_radps * Vec3(n(rng), n(rng), n(rng));
      log.imu.push_back(s);
    }
  }
  int k = 0;
  for (double t = t0_s; t <= t1_s; t += 0.0025, ++k) {
    const int a = k % 8, b = (k + 1) % 8;
    const Vec3 p_tag = tagPosition(truth(t).p, Quat::Identity(), kUtilTagOffset_b);
    double z = range(p_tag, anchors.find(b)->m) - range(p_tag, anchors.find(a)->m) + sigma_m * n(rng);
    if (tdoa_offset) z += tdoa_offset(t, a);
    log.tdoa.push_back({t, a, b, z});
  }
  return log;
}

/// Height z [m], vertical velocity vz [m/s] and acceleration az [m/s²] of a take-off.
struct Vertical {
  double z, vz, az;
};

/// 2 s on the floor at 0.05 m, a 1 m climb (±1 m/s² for 1 s each), then hover at 1.05 m.
inline Vertical takeoffProfile(double t) {
  const double tc = t - 2.0;
  if (tc <= 0.0) return {0.05, 0.0, 0.0};
  if (tc <= 1.0) return {0.05 + 0.5 * tc * tc, tc, 1.0};
  if (tc <= 2.0) {
    const double s = tc - 1.0;
    return {0.55 + s - 0.5 * s * s, 1.0 - s, -1.0};
  }
  return {1.05, 0.0, 0.0};
}

/// A synthetic take-off flight at (0.8, −0.5) in the arena, level attitude, following takeoffProfile().
struct TakeoffLogSpec {
  double duration_s = 10.0;
  unsigned seed = 1;  ///< used by takeoffLog(spec) without an rng
  double acc_noise_mps2 = 0.3;      ///< white noise per accelerometer axis and sample
  double gyro_noise_radps = 0.02;   ///< white noise per gyroscope axis and sample
  /// Gyroscope noise while on the floor (t < 2 s): the frame shakes against the floor with the motors running
  /// (util-pilot: high-passed gyro rms ≈ 0.36 rad/s median), the estimator's evidence of ground contact (F18).
  double floor_gyro_noise_radps = 0.25;
  double tdoa_noise_m = 0.1;        ///< white noise per TDoA sample
  /// Accelerometer z bias [m/s²] at time t (none by default).
  std::function<double(double)> acc_bias_z = [](double) { return 0.0; };
  /// Height offset [m] of the position the TDoA are generated from, at time t (a UWB height bias; none by default).
  std::function<double(double)> tdoa_dz = [](double) { return 0.0; };
};

/// IMU at 1 kHz and TDoA at 400 Hz on the neighbour pairs (k, k+1 mod 8) of arenaAnchors(); no ToF. The noise
/// is drawn from `rng` (seeded with spec.seed by the caller), which a caller may go on drawing from.
inline SensorLog takeoffLog(const TakeoffLogSpec& spec, std::mt19937& rng) {
  const AnchorTable anchors = arenaAnchors();
  const Vec3 p0(0.8, -0.5, 0.0);
  std::normal_distribution<double> n(0.0, 1.0);
  SensorLog log;
  for (double t = 0.0; t <= spec.duration_s; t += 0.001) {
    TimedImu s;
    s.t_s = t;
    s.imu.b_acc_mps2 = Vec3(0, 0, takeoffProfile(t).az + kGravity_mps2 + spec.acc_bias_z(t)) +
                       spec.acc_noise_mps2 * Vec3(n(rng), n(rng), n(rng));
    s.imu.b_gyro_radps = (t < 2.0 ? spec.floor_gyro_noise_radps : spec.gyro_noise_radps) * Vec3(n(rng), n(rng), n(rng));
    log.imu.push_back(s);
  }
  int k = 0;
  for (double t = 0.0; t <= spec.duration_s; t += 0.0025, ++k) {
    const int a = k % 8, b = (k + 1) % 8;
    const Vec3 p = p0 + Vec3(0, 0, takeoffProfile(t).z + spec.tdoa_dz(t));
    const Vec3 p_tag = tagPosition(p, Quat::Identity(), kUtilTagOffset_b);
    const double z = range(p_tag, anchors.find(b)->m) - range(p_tag, anchors.find(a)->m) + spec.tdoa_noise_m * n(rng);
    log.tdoa.push_back({t, a, b, z});
  }
  return log;
}

inline SensorLog takeoffLog(const TakeoffLogSpec& spec) {
  std::mt19937 rng(spec.seed);
  return takeoffLog(spec, rng);
}

}  // namespace uwb::filtertest
