/** @file SimVsRealTest.cpp
 *  @brief Simulated vs real residual statistics: each util-pilot circle flight next to a simulated flight of the
 *  same shape, ω, duration and anchors (constant yaw, as flown). Prints the table quoted in
 *  docs/math/simulation.md §5 and checks that the simulated numbers are of the same size as the real ones.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/TestSupport.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/ResidualProfile.h"

namespace uwb::sim {
namespace {

struct RealFlight {
  const char* name;
  TrajectoryShape shape;
  double omega_rps;
};

double largestPairMedian(const ResidualProfile& s) {
  double m = 0.0;
  for (const auto& [pair, ps] : s.pairs) {
    if (ps.n >= 50) m = std::max(m, std::abs(ps.median_m));
  }
  return m;
}

std::string row(const std::string& label, const ResidualProfile& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "| %-22s | %+.3f | %.3f | %.3f | %.3f | %.2f | %.2f | %.2f | %.4f |", label.c_str(),
                s.overall.median_m, s.overall.mean_abs_dev_m, s.overall.std_m, largestPairMedian(s), s.autocorrelation[0].second,
                s.autocorrelation[1].second, s.autocorrelation[2].second, s.outlier_fraction);
  return buf;
}

TEST(SimVsReal, AirborneResidualStatisticsAreOfTheSameSize) {
  const RealFlight flights[] = {{"0425-traj1", TrajectoryShape::kCircle, 0.4},
                                {"0425-traj2", TrajectoryShape::kCircle, 0.6},
                                {"0425-traj3", TrajectoryShape::kCircle, 0.8},
                                {"0425-traj4", TrajectoryShape::kCircle, 1.0},
                                {"0425-traj7", TrajectoryShape::kCircleSine, 0.6}};
  const auto first = test::pilotFlight(flights[0].name);
  UWB_REQUIRE_REAL_DATA(first);
  const AnchorSurvey survey = readAnchorSurvey(test::pilotSurvey("0425").string());
  std::printf("| flight | median [m] | MAD [m] | std [m] | max pair |median| [m] | ac 0.1 s | ac 0.3 s | ac 1 s | >1 m |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  double real_mad_sum = 0.0, sim_mad_sum = 0.0;
  std::uint64_t seed = 1;
  for (const RealFlight& rf : flights) {
    // GIVEN a real flight and a simulated flight of the same kind
    const auto path = test::pilotFlight(rf.name);
    if (!path) continue;
    const Flight real = readFlightCsv(path->string());
    const auto [t0, t1] = real.timeSpan();
    Scenario sc = makeScenario(survey, rf.shape, std::max(30.0, t1 - t0));
    sc.trajectory.omega_rps = rf.omega_rps;
    sc.trajectory.yaw_mode = YawMode::kConstant;
    const SimResult sim = simulateFlight(sc, SimParams{}, seed++);
    // WHEN we compute the airborne residual statistics of both the same way
    const ResidualProfile r = residualProfile(real, survey, Phase::kAirborne);
    const ResidualProfile s = residualProfile(sim.flight, sim.survey, Phase::kAirborne);
    std::printf("%s\n%s\n", row(std::string("real ") + rf.name, r).c_str(),
                row(std::string("sim  ") + toString(rf.shape) + " ω=" + std::to_string(rf.omega_rps).substr(0, 3), s)
                    .c_str());
    // THEN the simulated flight is within the real range
    EXPECT_LT(std::abs(s.overall.median_m), 0.03) << rf.name;
    EXPECT_GT(s.overall.mean_abs_dev_m, 0.5 * r.overall.mean_abs_dev_m) << rf.name;
    EXPECT_LT(s.overall.mean_abs_dev_m, 2.0 * r.overall.mean_abs_dev_m) << rf.name;
    real_mad_sum += r.overall.mean_abs_dev_m;
    sim_mad_sum += s.overall.mean_abs_dev_m;
  }
  std::printf("mean MAD: real %.3f m, simulated %.3f m\n", real_mad_sum / 5.0, sim_mad_sum / 5.0);
}

TEST(SimVsReal, FloorLevelBiasFadesWithinTheSameHeight) {
  // S18: the floor-level bias of the simulator fades with the height above the floor as in the real take-offs
  const char* names[] = {"0425-traj1", "0425-traj2", "0425-traj3", "0425-traj4", "0425-traj7"};
  const auto first = test::pilotFlight(names[0]);
  UWB_REQUIRE_REAL_DATA(first);
  const AnchorSurvey survey = readAnchorSurvey(test::pilotSurvey("0425").string());
  const std::vector<double> edges = {-1.0, 0.02, 0.05, 0.08, 0.12, 0.17, 0.25, 0.4};
  // GIVEN the real take-offs and simulated flights of the same anchors, pooled (median of the per-flight medians)
  std::vector<std::vector<double>> real(edges.size() - 1), sim(edges.size() - 1);
  std::uint64_t seed = 1;
  for (const char* name : names) {
    const auto path = test::pilotFlight(name);
    if (!path) continue;
    const Flight f = readFlightCsv(path->string());
    // WHEN the median |residual| is taken per height above the floor, before the body first rises 0.8 m
    const std::vector<HeightBin> r = takeoffResidualProfile(f, survey, edges);
    const SimResult s = simulateFlight(makeScenario(survey, TrajectoryShape::kCircle, 30.0), SimParams{}, seed++);
    const std::vector<HeightBin> q = takeoffResidualProfile(s.flight, s.survey, edges);
    for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
      if (r[k].n >= 20) real[k].push_back(r[k].median_abs_m);
      if (q[k].n >= 20) sim[k].push_back(q[k].median_abs_m);
    }
  }
  std::printf("| height above the floor [m] | real median |r| [m] | simulated [m] |\n|---|---|---|\n");
  const auto median = [](std::vector<double> v) { return v.empty() ? std::nan("") : residualStats(v).median_m; };
  std::vector<double> mr, ms;
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    mr.push_back(median(real[k]));
    ms.push_back(median(sim[k]));
    std::printf("| %.2f…%.2f | %.2f | %.2f |\n", std::max(edges[k], 0.0), edges[k + 1], mr.back(), ms.back());
  }
  // THEN both are metres on the floor, and both have faded to the airborne size (< 0.4 m) from 12 cm on
  EXPECT_GT(mr[0], 1.5);
  EXPECT_GT(ms[0], 1.5);
  for (std::size_t k = 4; k + 1 < edges.size(); ++k) {
    EXPECT_LT(mr[k], 0.4) << "real, bin " << k;
    EXPECT_LT(ms[k], 0.4) << "simulated, bin " << k;
  }
  // and halfway up the fade (5–8 cm) the simulated bias is within a factor 2 of the real one
  EXPECT_GT(ms[2], 0.5 * mr[2]);
  EXPECT_LT(ms[2], 2.0 * mr[2]);
}

}  // namespace
}  // namespace uwb::sim
