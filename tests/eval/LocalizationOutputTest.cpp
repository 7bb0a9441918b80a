/** @file LocalizationOutputTest.cpp
 *  @brief What localizeFlight hands to users beside the pose: the IMU biases the filter estimated (trajectory CSV
 *         columns acc_bias_*, gyro_bias_*), NaN where the model has no bias states.
 */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/eval/Localization.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace uwb {
namespace {

TEST(LocalizationOutput, TheTrajectoryCarriesTheEstimatedImuBiasesAndNoneWithoutImu) {
  // GIVEN a simulated circle flight whose IMU has turn-on biases (SimParams: 0.1 m/s², per axis, seed 3)
  const sim::Scenario scenario = sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kCircle, 30.0);
  const sim::SimResult sim = sim::simulateFlight(scenario, sim::SimParams{}, /*seed=*/3);
  // WHEN it is localized with the IMU-driven filter and with the TDoA-only model
  const LocalizationRun imu = localizeFlight(sim.flight, sim.survey, {});
  LocalizationOptions tdoa_only;
  tdoa_only.tdoa_only = true;
  const LocalizationRun cv = localizeFlight(sim.flight, sim.survey, tdoa_only);
  // THEN every IMU-driven sample has its biases, and at the end the thrust-axis accelerometer bias (observable in
  // flight under the thrust model; the horizontal ones are not) is the simulated one (0.128 m/s²) within 0.03 m/s²
  ASSERT_FALSE(imu.trajectory.empty());
  for (const TrajectorySample& s : imu.trajectory) ASSERT_TRUE(s.hasImuBias()) << "t = " << s.t_s;
  const double truth_z = sim.imu_truth.back().b_acc_bias.z();
  ASSERT_GT(std::abs(truth_z), 0.1);  // premise: a bias to find
  EXPECT_NEAR(imu.trajectory.back().b_acc_bias.z(), truth_z, 0.03);
  // AND the TDoA-only model, which has no bias states, reports none
  ASSERT_FALSE(cv.trajectory.empty());
  for (const TrajectorySample& s : cv.trajectory) ASSERT_FALSE(s.hasImuBias()) << "t = " << s.t_s;
}

}  // namespace
}  // namespace uwb
