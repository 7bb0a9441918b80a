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

}  // namespace
}  // namespace uwb::sim
