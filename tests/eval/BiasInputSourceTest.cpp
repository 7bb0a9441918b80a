/** @file BiasInputSourceTest.cpp
 *  @brief GP inputs of the training data from the filter's estimate (BiasInputSource::kFilterEstimate): the target
 *         ε still comes from the ground truth, the features from the uncorrected filter, and every measurement is
 *         counted under exactly one rule.
 */
#include <gtest/gtest.h>

#include "uwb/eval/BiasDataset.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace uwb {
namespace {

TEST(BiasInputSource, EstimatedInputsKeepTargetsAndMoveFeaturesByTheFilterError) {
  // GIVEN a simulated circle flight with IMU and ground truth
  const sim::Scenario scenario = sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kCircle, 30.0);
  const sim::SimResult sim = sim::simulateFlight(scenario, sim::SimParams{}, /*seed=*/3);
  BiasDatasetParams truth_params;
  BiasDatasetParams estimate_params;
  estimate_params.inputs = BiasInputSource::kFilterEstimate;
  // WHEN we build the training data with both input sources
  const BiasDataset truth = buildBiasDataset({sim.flight}, sim.survey, truth_params);
  const BiasDataset estimate = buildBiasDataset({sim.flight}, sim.survey, estimate_params);
  // THEN every measurement is accounted for once, and the estimate covers nearly all airborne samples
  const BiasFlightReport& r = estimate.flights.at(0);
  EXPECT_EQ(r.n_unknown_anchor + r.n_no_ground_truth + r.n_pose_glitch + r.n_on_ground + r.n_non_neighbour +
                r.n_outlier + r.n_no_estimate + r.n_used,
            r.n_measurements);
  ASSERT_GT(estimate.samples.size(), truth.samples.size() * 9 / 10);
  // AND the targets are the ground-truth errors (paper eq. 6), while the features sit near, not on, the truth
  std::size_t j = 0;
  double sum_sq_offset = 0.0;
  std::size_t n_compared = 0;
  for (const BiasSample& s : estimate.samples) {
    while (j < truth.samples.size() && truth.samples[j].t_s < s.t_s) ++j;
    if (j == truth.samples.size() || truth.samples[j].t_s != s.t_s) continue;
    EXPECT_DOUBLE_EQ(s.error_m, truth.samples[j].error_m);
    sum_sq_offset += (s.feature.w_p_b - truth.samples[j].feature.w_p_b).squaredNorm();
    ++n_compared;
  }
  ASSERT_GT(n_compared, estimate.samples.size() * 9 / 10);
  const double rms_offset_m = std::sqrt(sum_sq_offset / n_compared);
  EXPECT_GT(rms_offset_m, 1e-3) << "features must come from the filter, not the truth";
  EXPECT_LT(rms_offset_m, 0.6) << "the uncorrected filter should track the simulated flight";
  EXPECT_NE(estimate.reportText().find("the filter's estimate"), std::string::npos);
}

TEST(BiasInputSource, NamesRoundTripAndUnknownNameIsAnError) {
  EXPECT_EQ(biasInputSourceFromString(toString(BiasInputSource::kGroundTruth)), BiasInputSource::kGroundTruth);
  EXPECT_EQ(biasInputSourceFromString(toString(BiasInputSource::kFilterEstimate)), BiasInputSource::kFilterEstimate);
  EXPECT_THROW(biasInputSourceFromString("gps"), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
