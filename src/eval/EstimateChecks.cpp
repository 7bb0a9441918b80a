/** @file EstimateChecks.cpp
 *  @brief Coverage, steps, floor and settling checks of a localized flight.
 */
#include "uwb/eval/EstimateChecks.h"

#include <algorithm>
#include <cmath>

namespace uwb {
namespace {

/// σ of the estimate at t, linear between the neighbouring samples (`estimate` sorted by time, non-empty).
Vec3 sigmaAt(const Trajectory& estimate, double t_s) {
  const auto it = std::lower_bound(estimate.begin(), estimate.end(), t_s,
                                   [](const TrajectorySample& s, double t) { return s.t_s < t; });
  if (it == estimate.begin()) return estimate.front().sigma_p_m;
  if (it == estimate.end()) return estimate.back().sigma_p_m;
  const TrajectorySample& a = *(it - 1);
  const TrajectorySample& b = *it;
  const double w = b.t_s > a.t_s ? (t_s - a.t_s) / (b.t_s - a.t_s) : 0.0;
  return (1.0 - w) * a.sigma_p_m + w * b.sigma_p_m;
}

/// Coverage of the reported σ, airborne.
void checkCoverage(const Trajectory& estimate, const std::vector<PositionErrorSample>& samples, EstimateChecks& c) {
  for (const PositionErrorSample& s : samples) {
    if (!s.airborne) continue;
    const Vec3 sigma = sigmaAt(estimate, s.t_s);
    for (int k = 0; k < 3; ++k) {
      const double e = std::abs(s.error_m(k));
      c.coverage_1sigma(k) += e <= sigma(k) ? 1.0 : 0.0;
      c.coverage_2sigma(k) += e <= 2.0 * sigma(k) ? 1.0 : 0.0;
    }
    ++c.n_coverage;
  }
  if (c.n_coverage > 0) {
    c.coverage_1sigma /= static_cast<double>(c.n_coverage);
    c.coverage_2sigma /= static_cast<double>(c.n_coverage);
  }
}

/// Airborne / on-ground state of the truth at a time: the nearest compared sample (`samples` sorted by time);
/// *known is false when none lies within 0.1 s.
bool truthAirborne(const std::vector<PositionErrorSample>& samples, double t_s, bool* known) {
  const auto it = std::lower_bound(samples.begin(), samples.end(), t_s,
                                   [](const PositionErrorSample& s, double t) { return s.t_s < t; });
  *known = false;
  const PositionErrorSample* best = nullptr;
  if (it != samples.end()) best = &*it;
  if (it != samples.begin() && (!best || t_s - (it - 1)->t_s < best->t_s - t_s)) best = &*(it - 1);
  if (!best || std::abs(best->t_s - t_s) > 0.1) return false;
  *known = true;
  return best->airborne;
}

/// The error before take-off, the largest airborne step and the estimate's height while the truth is on the ground
/// after the first take-off.
void checkStepsAndFloor(const Trajectory& estimate, const std::vector<PositionErrorSample>& samples,
                        const EstimateCheckParams& params, EstimateChecks& c) {
  double t_first_air = std::numeric_limits<double>::infinity();
  for (const PositionErrorSample& s : samples)
    if (s.airborne) {
      t_first_air = s.t_s;
      break;
    }
  for (const PositionErrorSample& s : samples) {
    if (s.t_s >= t_first_air) break;
    c.max_error_before_takeoff_m = std::isnan(c.max_error_before_takeoff_m)
                                       ? s.error_norm_m
                                       : std::max(c.max_error_before_takeoff_m, s.error_norm_m);
  }
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const TrajectorySample& e = estimate[i];
    bool known = false;
    const bool air = truthAirborne(samples, e.t_s, &known);
    if (!known) continue;
    if (air && i > 0 && e.t_s - estimate[i - 1].t_s <= params.step_max_dt_s)
      c.max_airborne_step_m = std::max(c.max_airborne_step_m, (e.w_p_b - estimate[i - 1].w_p_b).norm());
    if (!air && e.t_s > t_first_air) {
      const double z = e.w_p_b.z();
      c.min_z_on_ground_m = std::isnan(c.min_z_on_ground_m) ? z : std::min(c.min_z_on_ground_m, z);
      c.max_z_on_ground_m = std::isnan(c.max_z_on_ground_m) ? z : std::max(c.max_z_on_ground_m, z);
      if (z < params.floor_z_m - params.floor_tolerance_m || z > params.ceiling_z_m) c.floor_or_ceiling_violated = true;
    }
  }
}

/// Settling: the last airborne sample above the threshold; the errors 3 s and more after the start.
void checkSettling(const std::vector<PositionErrorSample>& samples, const EstimateCheckParams& params,
                   EstimateChecks& c) {
  double t_last_bad = -std::numeric_limits<double>::infinity();
  bool any_air = false;
  const double t_start = std::isnan(params.t_start_s) ? c.first_estimate_t_s : params.t_start_s;
  double sum_early = 0.0;
  std::size_t n_early = 0;
  for (const PositionErrorSample& s : samples) {
    if (!s.airborne || s.t_s < c.first_estimate_t_s) continue;
    any_air = true;
    if (s.error_norm_m > params.settle_error_m) t_last_bad = s.t_s;
    if (s.t_s > t_start + 3.0) c.max_error_after_3s_m = std::max(c.max_error_after_3s_m, s.error_norm_m);
    if (s.t_s >= t_start + 3.0 && s.t_s <= t_start + 5.0) {
      sum_early += s.error_norm_m * s.error_norm_m;
      ++n_early;
    }
  }
  if (n_early > 0) c.rmse_3_to_5s_m = std::sqrt(sum_early / static_cast<double>(n_early));
  if (any_air) {
    if (std::isinf(t_last_bad)) c.settle_time_s = 0.0;
    else if (t_last_bad < samples.back().t_s) c.settle_time_s = t_last_bad - c.first_estimate_t_s;
  }
}

}  // namespace

EstimateChecks checkEstimate(const Trajectory& estimate, const TrajectoryMetrics& metrics,
                             const EstimateCheckParams& params) {
  EstimateChecks c;
  if (estimate.empty()) return c;
  c.first_estimate_t_s = estimate.front().t_s;
  const std::vector<PositionErrorSample>& samples = metrics.samples;  // sorted by time (ground-truth order)
  checkCoverage(estimate, samples, c);
  checkStepsAndFloor(estimate, samples, params, c);
  checkSettling(samples, params, c);
  return c;
}

}  // namespace uwb
