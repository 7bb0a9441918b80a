/** @file Trajectory.h
 *  @brief Smooth (C3) quadrotor reference flights: ground → take-off → pattern → landing → ground.
 *
 *  The flat outputs of a quadrotor are position and yaw (Mellinger & Kumar 2011); this file produces them
 *  with analytic first and second derivatives. Patterns: the paper's zigzag training flight (a Lissajous
 *  raster covering the room) and circular test flight, the UTIL circle with a vertical sine, and a figure
 *  eight. docs/math/simulation.md (S1)–(S6).
 */
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "uwb/core/Types.h"

namespace uwb::sim {

enum class TrajectoryShape { kZigzag, kCircle, kCircleSine, kFigureEight, kHover };

/// "zigzag" | "circle" | "circle-sine" | "figure8" | "hover" (still at the pattern centre, height_m); throws std::invalid_argument otherwise.
TrajectoryShape parseTrajectoryShape(std::string_view name);
std::string toString(TrajectoryShape shape);

/// How the drone yaws while flying. kConstantRate: ψ = ψ0 + yaw_rate · s(t) (the paper: anchors seen from all
/// sides); kConstant: ψ = ψ0 throughout (the util-pilot flights).
enum class YawMode { kConstantRate, kConstant };

struct TrajectoryParams {
  TrajectoryShape shape = TrajectoryShape::kCircle;
  double duration_s = 60.0;        ///< whole flight including the ground phases
  double ground_before_s = 4.0;    ///< sitting on the ground before take-off
  double ground_after_s = 4.0;     ///< sitting on the ground after landing
  double takeoff_s = 3.0;          ///< vertical climb from the ground to the pattern's start
  double landing_s = 3.0;          ///< vertical descent from the pattern's end
  double speed_ramp_s = 3.0;       ///< time warp ramp at both ends of the pattern (S3)
  double ground_z_m = 0.03;        ///< body-origin height when sitting on the ground (util-pilot: 0.03 m)

  Vec2 w_center_xy = Vec2::Zero();  ///< pattern centre in the world frame [m]
  // circle / circle-sine (util-pilot: r = 1.5 m, z = 1.5 m, ω = 0.4…1.0 rad/s, sine 0.5 m at 0.5 ω)
  double radius_m = 1.5;
  double height_m = 1.5;
  double omega_rps = 0.6;              ///< angular rate along the circle / figure eight [rad/s]
  double sine_amplitude_m = 0.5;       ///< circle-sine vertical amplitude
  double sine_omega_ratio = 0.5;       ///< circle-sine vertical angular rate / omega_rps
  // figure eight (lemniscate of Gerono): half-length along x, half-width along y
  double figure8_half_length_m = 2.0;
  double figure8_half_width_m = 1.2;
  double figure8_omega_rps = 0.3;      ///< parameter rate of the figure eight (peak speed ≈ 0.94 m/s)
  // zigzag (Lissajous raster): half-extents, height band, speed of the fast sweep
  double zigzag_half_x_m = 2.4;
  double zigzag_half_y_m = 2.8;
  double zigzag_z_min_m = 0.8;
  double zigzag_z_max_m = 2.2;
  double zigzag_speed_mps = 1.0;       ///< peak speed of the fast x sweep
  double zigzag_sweep_ratio = 6.7;     ///< fast-x / slow-y angular-rate ratio (non-integer: no repeats)

  YawMode yaw_mode = YawMode::kConstantRate;
  double yaw0_rad = 0.0;
  double yaw_rate_rps = 0.5;  ///< used with kConstantRate [rad/s]

  /// Pattern time (duration minus ground, take-off and landing) [s].
  double patternDuration_s() const {
    return duration_s - ground_before_s - ground_after_s - takeoff_s - landing_s;
  }
  /// Throws std::invalid_argument naming the offending field.
  void validate() const;
};

/// Flat outputs and their derivatives at one instant (world frame, SI).
struct FlatState {
  Vec3 w_p = Vec3::Zero();  ///< body origin [m]
  Vec3 w_v = Vec3::Zero();  ///< [m/s]
  Vec3 w_a = Vec3::Zero();  ///< [m/s²]
  double yaw_rad = 0.0;
  bool on_ground = false;   ///< in a ground phase (before take-off starts or after landing ends)
};

/// One axis of a pattern: c + Σ_k A_k sin(ω_k s + φ_k) (S4).
struct SinusoidAxis {
  struct Term {
    double amplitude = 0.0;
    double omega = 0.0;
    double phase = 0.0;
  };
  double offset = 0.0;
  std::array<Term, 2> terms{};
};

/// A reference flight, immutable after construction. evaluate() is cheap (a few sin/cos).
class Trajectory {
 public:
  explicit Trajectory(const TrajectoryParams& params);

  /// Flat state at time t_s ∈ [0, duration]; clamps outside (sitting on the ground).
  FlatState evaluate(double t_s) const;
  double duration_s() const { return params_.duration_s; }
  const TrajectoryParams& params() const { return params_; }

 private:
  /// Pattern position and its first two derivatives w.r.t. the pattern parameter s (S4).
  void pattern(double s, Vec3* p, Vec3* dp, Vec3* ddp) const;

  TrajectoryParams params_;
  std::array<SinusoidAxis, 3> axes_{};
  double s_end_ = 0.0;  ///< pattern parameter at the end of the pattern
};

/// Septic smoothstep σ(x) = 35x⁴ − 84x⁵ + 70x⁶ − 20x⁷ on [0, 1] (clamped) and its derivatives (S2).
double smoothstep7(double x, double* d1 = nullptr, double* d2 = nullptr);

}  // namespace uwb::sim
