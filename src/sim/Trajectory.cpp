/** @file Trajectory.cpp
 *  @brief Reference flights: ground, C3 take-off, time-warped sinusoid pattern, C3 landing, ground.
 *  docs/math/simulation.md (S1)–(S6).
 */
#include "uwb/sim/Trajectory.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace uwb::sim {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("TrajectoryParams: " + what);
}

/// ∫₀ˣ σ(u) du = 7x⁵ − 14x⁶ + 10x⁷ − 2.5x⁸ (S3); equals 1/2 at x = 1.
double smoothstep7Integral(double x) {
  x = std::clamp(x, 0.0, 1.0);
  const double x2 = x * x;
  const double x5 = x2 * x2 * x;
  return x5 * (7.0 + x * (-14.0 + x * (10.0 - 2.5 * x)));
}

}  // namespace

TrajectoryShape parseTrajectoryShape(std::string_view name) {
  if (name == "zigzag") return TrajectoryShape::kZigzag;
  if (name == "circle") return TrajectoryShape::kCircle;
  if (name == "circle-sine") return TrajectoryShape::kCircleSine;
  if (name == "figure8") return TrajectoryShape::kFigureEight;
  if (name == "hover") return TrajectoryShape::kHover;
  throw std::invalid_argument("unknown trajectory '" + std::string(name) +
                              "' (expected zigzag, circle, circle-sine, figure8 or hover)");
}

std::string toString(TrajectoryShape shape) {
  switch (shape) {
    case TrajectoryShape::kZigzag: return "zigzag";
    case TrajectoryShape::kCircle: return "circle";
    case TrajectoryShape::kCircleSine: return "circle-sine";
    case TrajectoryShape::kFigureEight: return "figure8";
    case TrajectoryShape::kHover: return "hover";
  }
  return "?";
}

void TrajectoryParams::validate() const {
  require(std::isfinite(duration_s) && duration_s > 0.0, "duration_s must be positive");
  require(ground_before_s >= 0.0 && ground_after_s >= 0.0, "ground times must be >= 0");
  require(takeoff_s > 0.0 && landing_s > 0.0, "takeoff_s and landing_s must be positive");
  require(speed_ramp_s > 0.0, "speed_ramp_s must be positive");
  require(patternDuration_s() >= 2.0 * speed_ramp_s,
          "duration_s = " + std::to_string(duration_s) +
              " s is too short: it must exceed ground, take-off, landing and two speed ramps (" +
              std::to_string(ground_before_s + ground_after_s + takeoff_s + landing_s + 2.0 * speed_ramp_s) +
              " s)");
  require(std::isfinite(ground_z_m), "ground_z_m must be finite");
  require(radius_m > 0.0 && height_m > ground_z_m, "radius_m > 0 and height_m > ground_z_m required");
  require(omega_rps > 0.0 && figure8_omega_rps > 0.0, "omega_rps and figure8_omega_rps must be positive");
  require(sine_amplitude_m >= 0.0 && sine_amplitude_m < height_m - ground_z_m,
          "sine_amplitude_m must be in [0, height_m − ground_z_m)");
  require(sine_omega_ratio > 0.0, "sine_omega_ratio must be positive");
  require(figure8_half_length_m > 0.0 && figure8_half_width_m > 0.0, "figure-eight extents must be positive");
  require(zigzag_half_x_m > 0.0 && zigzag_half_y_m > 0.0, "zigzag extents must be positive");
  require(zigzag_z_min_m > ground_z_m && zigzag_z_max_m >= zigzag_z_min_m,
          "zigzag height band invalid: need ground_z_m < zigzag_z_min_m <= zigzag_z_max_m, got " +
              std::to_string(ground_z_m) + ", " + std::to_string(zigzag_z_min_m) + ", " +
              std::to_string(zigzag_z_max_m) + " m (checked for every shape)");
  require(zigzag_speed_mps > 0.0 && zigzag_sweep_ratio > 1.0, "zigzag speed > 0 and sweep ratio > 1 required");
  require(std::isfinite(yaw0_rad) && std::isfinite(yaw_rate_rps), "yaw must be finite");
  require(std::abs(yaw_rate_rps) <= 6.0, "yaw_rate_rps must be within ±6 rad/s");
}

double smoothstep7(double x, double* d1, double* d2) {
  // docs/math/simulation.md (S2): σ(x) = 35x⁴ − 84x⁵ + 70x⁶ − 20x⁷; σ', σ'', σ''' vanish at 0 and 1 (C3 joins).
  x = std::clamp(x, 0.0, 1.0);
  const double x2 = x * x;
  const double x3 = x2 * x;
  if (d1 != nullptr) *d1 = 140.0 * x3 * (1.0 - x) * (1.0 - x) * (1.0 - x);
  if (d2 != nullptr) *d2 = 420.0 * x2 * (1.0 - x) * (1.0 - x) * (1.0 - 2.0 * x);
  return x2 * x2 * (35.0 + x * (-84.0 + x * (70.0 - 20.0 * x)));
}

Trajectory::Trajectory(const TrajectoryParams& params) : params_(params) {
  params_.validate();
  const TrajectoryParams& p = params_;
  const double cx = p.w_center_xy.x();
  const double cy = p.w_center_xy.y();
  SinusoidAxis& x = axes_[0];
  SinusoidAxis& y = axes_[1];
  SinusoidAxis& z = axes_[2];
  x.offset = cx;
  y.offset = cy;
  // docs/math/simulation.md (S4): every pattern is c + Σ A sin(ω s + φ) per axis.
  switch (p.shape) {
    case TrajectoryShape::kCircle:
    case TrajectoryShape::kCircleSine:
      x.terms[0] = {p.radius_m, p.omega_rps, 0.5 * kPi};  // r cos(ω s)
      y.terms[0] = {p.radius_m, p.omega_rps, 0.0};        // r sin(ω s)
      z.offset = p.height_m;
      if (p.shape == TrajectoryShape::kCircleSine) {
        z.terms[0] = {p.sine_amplitude_m, p.sine_omega_ratio * p.omega_rps, 0.0};  // UTIL: 0.5 sin(0.5 ω t)
      }
      break;
    case TrajectoryShape::kHover:  // still at (cx, cy, height): every term zero
      z.offset = p.height_m;
      break;
    case TrajectoryShape::kFigureEight:
      // lemniscate of Gerono: x = L sin(ω s), y = W sin(2 ω s)
      x.terms[0] = {p.figure8_half_length_m, p.figure8_omega_rps, 0.0};
      y.terms[0] = {p.figure8_half_width_m, 2.0 * p.figure8_omega_rps, 0.0};
      z.offset = p.height_m;
      break;
    case TrajectoryShape::kZigzag: {
      // Lissajous raster: a fast sweep along x while y drifts slowly across the room, height oscillating.
      const double wx = p.zigzag_speed_mps / p.zigzag_half_x_m;
      x.terms[0] = {p.zigzag_half_x_m, wx, 0.0};
      y.terms[0] = {p.zigzag_half_y_m, wx / p.zigzag_sweep_ratio, 0.0};
      z.offset = 0.5 * (p.zigzag_z_min_m + p.zigzag_z_max_m);
      z.terms[0] = {0.5 * (p.zigzag_z_max_m - p.zigzag_z_min_m), wx / (0.63 * p.zigzag_sweep_ratio), 0.0};
      break;
    }
  }
  s_end_ = p.patternDuration_s() - p.speed_ramp_s;  // (S3): s(T_p) = T_p − T_r
}

void Trajectory::pattern(double s, Vec3* pos, Vec3* dpos, Vec3* ddpos) const {
  for (int k = 0; k < 3; ++k) {
    const SinusoidAxis& axis = axes_[static_cast<std::size_t>(k)];
    double v = axis.offset;
    double d = 0.0;
    double dd = 0.0;
    for (const SinusoidAxis::Term& term : axis.terms) {
      if (term.amplitude == 0.0) continue;
      const double arg = term.omega * s + term.phase;
      const double sn = std::sin(arg);
      const double cs = std::cos(arg);
      v += term.amplitude * sn;
      d += term.amplitude * term.omega * cs;
      dd -= term.amplitude * term.omega * term.omega * sn;
    }
    (*pos)[k] = v;
    (*dpos)[k] = d;
    (*ddpos)[k] = dd;
  }
}

namespace {

/// (S1) The vertical climb or descent from `from` to `to` (same x, y) over duration_s, at x = elapsed / duration_s;
/// at rest (before the climb, after the descent) on the ground with zero velocity and acceleration. No yaw.
FlatState verticalMove(const Vec3& from, const Vec3& to, double x, double duration_s, bool at_rest) {
  FlatState out;
  const Vec3 delta = to - from;
  double d1 = 0.0;
  double d2 = 0.0;
  const double sg = smoothstep7(x, &d1, &d2);
  out.w_p = from + delta * sg;
  out.w_v = at_rest ? Vec3::Zero() : Vec3(delta * d1 / duration_s);
  out.w_a = at_rest ? Vec3::Zero() : Vec3(delta * d2 / (duration_s * duration_s));
  out.on_ground = at_rest;
  return out;
}

}  // namespace

FlatState Trajectory::evaluate(double t_s) const {
  const TrajectoryParams& p = params_;
  const double t = std::clamp(t_s, 0.0, p.duration_s);
  const double t0 = p.ground_before_s;
  const double t1 = t0 + p.takeoff_s;
  const double tp = p.patternDuration_s();
  const double t2 = t1 + tp;
  const double t3 = t2 + p.landing_s;
  const double yaw_rate = p.yaw_mode == YawMode::kConstantRate ? p.yaw_rate_rps : 0.0;

  FlatState out;
  Vec3 P, dP, ddP;
  if (t < t1) {
    pattern(0.0, &P, &dP, &ddP);
    const Vec3 ground(P.x(), P.y(), p.ground_z_m);
    out = verticalMove(ground, P, (t - t0) / p.takeoff_s, p.takeoff_s, t < t0);  // (S1) vertical climb
    out.yaw_rad = p.yaw0_rad;
    return out;
  }
  if (t < t2) {
    // (S3) time warp: ṡ ramps from 0 to 1 with σ over T_r at both ends, so the pattern starts and ends at rest.
    const double tau = t - t1;
    const double tr = p.speed_ramp_s;
    double s = 0.0;
    double ds = 1.0;
    double dds = 0.0;
    if (tau < tr) {
      double d1 = 0.0;
      ds = smoothstep7(tau / tr, &d1);
      s = tr * smoothstep7Integral(tau / tr);
      dds = d1 / tr;
    } else if (tau > tp - tr) {
      const double u = (tp - tau) / tr;
      double d1 = 0.0;
      ds = smoothstep7(u, &d1);
      s = s_end_ - tr * smoothstep7Integral(u);
      dds = -d1 / tr;
    } else {
      s = 0.5 * tr + (tau - tr);
    }
    pattern(s, &P, &dP, &ddP);
    out.w_p = P;                            // (S5) p = P(s)
    out.w_v = dP * ds;                      //      v = P'(s) ṡ
    out.w_a = ddP * (ds * ds) + dP * dds;   //      a = P''(s) ṡ² + P'(s) s̈
    out.yaw_rad = p.yaw0_rad + yaw_rate * s;  // (S6) ψ = ψ0 + ψ̇ s(t)
    return out;
  }
  pattern(s_end_, &P, &dP, &ddP);
  const Vec3 ground(P.x(), P.y(), p.ground_z_m);
  out = verticalMove(P, ground, (t - t2) / p.landing_s, p.landing_s, t >= t3);  // (S1) vertical descent
  out.yaw_rad = p.yaw0_rad + yaw_rate * s_end_;
  return out;
}

}  // namespace uwb::sim
