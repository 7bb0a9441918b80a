/** @file ResidualProfile.cpp
 *  @brief TDoA residual profile against the pose stream (the numbers SOURCE.md reports for real flights).
 */
#include "uwb/sim/ResidualProfile.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "uwb/io/PoseTrack.h"
#include "uwb/sim/TdoaResiduals.h"

namespace uwb::sim {

namespace {

struct Residual {
  double t_s;
  double r_m;
};

}  // namespace

ResidualProfile residualProfile(const Flight& flight, const AnchorSurvey& survey, Phase phase,
                                double airborne_min_z_m, const Vec3& b_t_tag) {
  ResidualProfile out;
  if (flight.pose.size() < 2) return out;
  TdoaResidualParams rp;
  rp.b_t_tag = b_t_tag;
  rp.airborne_min_z_m = airborne_min_z_m;
  std::map<std::pair<int, int>, std::vector<Residual>> by_pair;
  std::vector<double> all;
  for (const TdoaResidual& r : tdoaResiduals(flight, survey, PoseTrack(flight), rp)) {
    if ((phase == Phase::kAirborne && !r.airborne) || (phase == Phase::kGround && r.airborne)) continue;
    by_pair[{r.id_a, r.id_b}].push_back({r.t_s, r.residual_m});
    all.push_back(r.residual_m);
  }
  out.overall = residualStats(all);
  if (all.empty()) return out;

  std::size_t n_out = 0;
  const double lags[] = {0.1, 0.3, 1.0, 5.0};
  std::vector<double> ac_sum(4, 0.0);
  std::vector<int> ac_n(4, 0);
  for (const auto& [pair, res] : by_pair) {
    std::vector<double> values(res.size());
    std::transform(res.begin(), res.end(), values.begin(), [](const Residual& x) { return x.r_m; });
    const ResidualStats ps = residualStats(values);
    const double pm = ps.mean_m;
    const double pv = ps.std_m * ps.std_m;
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

std::vector<HeightBin> takeoffResidualProfile(const Flight& flight, const AnchorSurvey& survey,
                                              const std::vector<double>& edges_m, double top_m, const Vec3& b_t_tag) {
  std::vector<HeightBin> out;
  for (std::size_t k = 0; k + 1 < edges_m.size(); ++k) out.push_back({edges_m[k], edges_m[k + 1], 0, std::nan("")});
  if (flight.pose.size() < 2 || out.empty()) return out;
  const double z_floor = flight.pose.front().w_p_b.z();
  double t_top = std::numeric_limits<double>::infinity();
  for (const PoseSample& p : flight.pose)
    if (p.w_p_b.z() - z_floor > top_m) {
      t_top = p.t_s;
      break;
    }
  TdoaResidualParams rp;
  rp.b_t_tag = b_t_tag;
  std::vector<std::vector<double>> abs_r(out.size());
  for (const TdoaResidual& r : tdoaResiduals(flight, survey, PoseTrack(flight), rp)) {
    if (r.t_s >= t_top) continue;
    const double h = r.w_p_b.z() - z_floor;
    for (std::size_t k = 0; k < out.size(); ++k)
      if (h >= out[k].h0_m && h < out[k].h1_m) abs_r[k].push_back(std::abs(r.residual_m));
  }
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].n = abs_r[k].size();
    if (out[k].n > 0) out[k].median_abs_m = residualStats(abs_r[k]).median_m;
  }
  return out;
}

}  // namespace uwb::sim
