/** @file ResidualStats.cpp
 *  @brief TDoA residual statistics against the pose stream (the numbers SOURCE.md reports for real flights).
 */
#include "uwb/sim/ResidualStats.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "uwb/model/TdoaModel.h"

namespace uwb::sim {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  const double upper = *mid;
  const double lower = *std::max_element(v.begin(), mid);
  return 0.5 * (lower + upper);
}

struct Residual {
  double t_s;
  double r_m;
};

}  // namespace

ResidualStats residualStats(const Flight& flight, const AnchorSurvey& survey, Phase phase, double airborne_min_z_m,
                            const Vec3& b_t_tag) {
  ResidualStats out;
  const std::vector<PoseSample>& pose = flight.pose;
  if (pose.size() < 2) return out;
  std::map<std::pair<int, int>, std::vector<Residual>> by_pair;
  std::vector<double> all;
  std::size_t k = 1;
  for (const TdoaMeasurement& m : flight.tdoa) {
    if (m.t_s < pose.front().t_s || m.t_s > pose.back().t_s) continue;
    if (!survey.contains(m.id_a) || !survey.contains(m.id_b)) continue;
    while (k + 1 < pose.size() && pose[k].t_s < m.t_s) ++k;
    while (k > 1 && pose[k - 1].t_s > m.t_s) --k;
    const PoseSample& p0 = pose[k - 1];
    const PoseSample& p1 = pose[k];
    const double span = p1.t_s - p0.t_s;
    const double f = span > 0.0 ? (m.t_s - p0.t_s) / span : 0.0;
    const Vec3 w_p_b = p0.w_p_b + f * (p1.w_p_b - p0.w_p_b);
    const bool airborne = w_p_b.z() >= airborne_min_z_m;
    if ((phase == Phase::kAirborne && !airborne) || (phase == Phase::kGround && airborne)) continue;
    const Quat& q = flight.pose_has_orientation ? p0.w_q_b : Quat::Identity();
    const double r = m.tdoa_m - predictTdoa(w_p_b, q, b_t_tag, survey.position(m.id_a), survey.position(m.id_b));
    by_pair[{m.id_a, m.id_b}].push_back({m.t_s, r});
    all.push_back(r);
  }
  out.count = all.size();
  if (all.empty()) return out;
  out.median_m = median(all);
  double abs_dev = 0.0;
  double mean = 0.0;
  for (double r : all) {
    abs_dev += std::abs(r - out.median_m);
    mean += r;
  }
  mean /= static_cast<double>(all.size());
  double var = 0.0;
  for (double r : all) var += (r - mean) * (r - mean);
  out.mean_abs_dev_m = abs_dev / static_cast<double>(all.size());
  out.std_m = std::sqrt(var / static_cast<double>(all.size()));

  std::size_t n_out = 0;
  const double lags[] = {0.1, 0.3, 1.0, 5.0};
  std::vector<double> ac_sum(4, 0.0);
  std::vector<int> ac_n(4, 0);
  for (const auto& [pair, res] : by_pair) {
    std::vector<double> values(res.size());
    std::transform(res.begin(), res.end(), values.begin(), [](const Residual& x) { return x.r_m; });
    PairResidualStats ps;
    ps.count = values.size();
    ps.median_m = median(values);
    const double pm = std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
    double pv = 0.0;
    for (double v : values) pv += (v - pm) * (v - pm);
    pv /= static_cast<double>(values.size());
    ps.std_m = std::sqrt(pv);
    for (double v : values) n_out += std::abs(v - ps.median_m) > 1.0 ? 1 : 0;
    out.pairs[pair] = ps;
    if (values.size() < 100 || !(pv > 0.0)) continue;
    for (std::size_t li = 0; li < 4; ++li) {
      // lag-L autocorrelation: pairs (i, j) with t_j the first sample at or after t_i + L, within 20 ms.
      double acc = 0.0;
      std::size_t n = 0;
      std::size_t j = 0;
      for (std::size_t i = 0; i < res.size(); ++i) {
        const double target = res[i].t_s + lags[li];
        while (j < res.size() && res[j].t_s < target) ++j;
        if (j >= res.size()) break;
        if (res[j].t_s - target < 0.02) {
          acc += (res[i].r_m - pm) * (res[j].r_m - pm);
          ++n;
        }
      }
      if (n > 0) {
        ac_sum[li] += acc / static_cast<double>(n) / pv;
        ++ac_n[li];
      }
    }
  }
  out.outlier_fraction = static_cast<double>(n_out) / static_cast<double>(all.size());
  for (std::size_t li = 0; li < 4; ++li) {
    out.autocorrelation.emplace_back(lags[li], ac_n[li] > 0 ? ac_sum[li] / ac_n[li] : 0.0);
  }
  return out;
}

}  // namespace uwb::sim
