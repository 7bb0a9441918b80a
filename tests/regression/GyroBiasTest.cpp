/** @file GyroBiasTest.cpp
 *  @brief A gyro with a turn-on bias (docs/math/filter.md F1, F18z): the bias read at rest gives the heading in
 *         flight, and a roll/pitch bias is learned in flight.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "uwb/eval/Localization.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/sim/FlightSimulator.h"

namespace uwb {
namespace {

double medianAirborneYawErrorDeg(const LocalizationRun& run, const Flight& flight) {
  const PoseTrack track(flight);
  const auto yaw = [](const Quat& q) {
    return std::atan2(2 * (q.w() * q.z() + q.x() * q.y()), 1 - 2 * (q.y() * q.y() + q.z() * q.z()));
  };
  std::vector<double> e;
  for (const TrajectorySample& s : run.trajectory) {
    const std::optional<PoseSample> t = track.interpolate(s.t_s);
    if (!t || t->w_p_b.z() < 0.3) continue;
    e.push_back(std::abs(std::remainder(yaw(s.w_q_b) - yaw(t->w_q_b), 2 * M_PI)) * 180 / M_PI);
  }
  if (e.empty()) return NAN;
  std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
  return e[e.size() / 2];
}

TEST(ZeroAngularRate, ASimulatedFlightStartingAtRestKnowsItsHeading) {
  // GIVEN a simulated circle that rests 4 s on the floor with the simulator's gyro turn-on bias (0.5°/s per axis)
  const sim::Scenario sc = sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kCircle, 40.0);
  const Flight flight = sim::simulateFlight(sc, sim::SimParams{}, 11).flight;
  // WHEN localized with and without the zero-angular-rate updates at rest
  LocalizationOptions with, without;
  without.params.rest_gyro_updates = false;
  const LocalizationRun a = localizeFlight(flight, sc.survey, with), b = localizeFlight(flight, sc.survey, without);
  // THEN the yaw is known in flight (median error 0.4° against 14° without: the z bias was unlearnable in flight)
  EXPECT_GT(a.summary.n_rest_gyro_updates, 10u);
  EXPECT_LT(medianAirborneYawErrorDeg(a, flight), 2.0);
  EXPECT_GT(medianAirborneYawErrorDeg(b, flight), 5.0);
  // AND the position is no worse
  ASSERT_TRUE(a.metrics && b.metrics);
  EXPECT_LT(a.metrics->airborne.rmse_m, 1.05 * b.metrics->airborne.rmse_m);
}

}  // namespace
}  // namespace uwb
