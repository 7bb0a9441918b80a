/** @file TrajectoryMetrics.cpp
 *  @brief Position error statistics of an estimated trajectory against ground truth.
 */
#include "uwb/eval/TrajectoryMetrics.h"

#include "uwb/io/PoseTrack.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace uwb {

void TrajectoryMetricsParams::validate() const {
  if (!std::isfinite(airborne_min_z_m)) throw std::invalid_argument("TrajectoryMetricsParams.airborne_min_z_m");
  if (!(max_interp_gap_s > 0.0)) throw std::invalid_argument("TrajectoryMetricsParams.max_interp_gap_s must be > 0");
}

namespace {
double percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const std::size_t i = static_cast<std::size_t>(std::floor(pos));
  const std::size_t j = std::min(i + 1, sorted.size() - 1);
  const double f = pos - static_cast<double>(i);
  return sorted[i] * (1.0 - f) + sorted[j] * f;
}
}  // namespace

double airborneRmseInWindow(const TrajectoryMetrics& m, double t0_s, double t1_s) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const PositionErrorSample& e : m.samples)
    if (e.airborne && e.t_s >= t0_s && e.t_s <= t1_s) {
      sum += e.error_norm_m * e.error_norm_m;
      ++n;
    }
  return n ? std::sqrt(sum / static_cast<double>(n)) : std::nan("");
}

PositionErrorStats positionErrorStats(const std::vector<PositionErrorSample>& samples, bool airborne_only) {
  PositionErrorStats s;
  std::vector<double> norms;
  Vec3 sq = Vec3::Zero();
  double sum = 0.0;
  for (const PositionErrorSample& e : samples) {
    if (airborne_only && !e.airborne) continue;
    sq += e.error_m.cwiseAbs2();
    norms.push_back(e.error_norm_m);
    sum += e.error_norm_m;
  }
  s.n = norms.size();
  if (s.n == 0) return s;
  const double n = static_cast<double>(s.n);
  s.rmse_axis_m = (sq / n).cwiseSqrt();
  s.rmse_m = std::sqrt(sq.sum() / n);
  s.mean_m = sum / n;
  std::sort(norms.begin(), norms.end());
  s.p50_m = percentile(norms, 0.50);
  s.p90_m = percentile(norms, 0.90);
  s.p99_m = percentile(norms, 0.99);
  s.max_m = norms.back();
  return s;
}

TrajectoryMetrics computeTrajectoryMetrics(const Trajectory& est, const std::vector<PoseSample>& truth,
                                           const TrajectoryMetricsParams& params) {
  params.validate();
  TrajectoryMetrics m;
  m.samples.reserve(truth.size());
  for (const PoseSample& gt : truth) {
    // io/PoseTrack.h: the one pose interpolation (position only here)
    const std::optional<PoseSample> at = interpolatePose(est, gt.t_s, params.max_interp_gap_s, false);
    if (!at) {
      ++m.n_truth_not_covered;
      continue;
    }
    const Vec3& p = at->w_p_b;
    PositionErrorSample e;
    e.t_s = gt.t_s;
    e.w_p_true = gt.w_p_b;
    e.w_p_est = p;
    e.error_m = p - gt.w_p_b;
    e.error_norm_m = e.error_m.norm();
    e.airborne = isAirborne(gt.w_p_b.z(), params.airborne_min_z_m);
    m.samples.push_back(e);
  }
  m.whole = positionErrorStats(m.samples, false);
  m.airborne = positionErrorStats(m.samples, true);
  return m;
}

}  // namespace uwb
