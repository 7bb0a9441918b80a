/** @file SwarmLocalizationTest.cpp
 *  @brief Cooperative localization in a simulated swarm (docs/math/message-passing.md G20–G22): the covariance-
 *         intersection fusion of neighbours' beliefs stays consistent (position NEES in a χ² band) where naive
 *         fusion of the same beliefs becomes over-confident, and cooperation helps an occluded agent.
 */
#include <gtest/gtest.h>

#include <cstdio>

#include "uwb/eval/SwarmLocalization.h"

namespace uwb {
namespace {

/// White TDoA noise with the filter's σ matched to it (as NeesConsistencyTest), so that the NEES measures the
/// cooperative fusion rather than the unmodelled TDoA bias.
sim::SimParams whiteNoiseSim() {
  sim::SimParams p;
  p.bias.antenna_rms_m = 0.0;
  p.bias.anchor_pattern_rms_m = 0.0;
  p.bias.anchor_offset_std_m = 0.0;
  p.bias.nlos_bias_m = 0.0;
  p.bias.multipath_std_m = 0.0;
  p.bias.outlier_probability = 0.0;
  p.bias.burst_probability = 0.0;
  p.bias.ground_effect = false;
  return p;
}

SwarmRunOptions matchedFilter(NeighbourFusion fusion, BeliefSource src = BeliefSource::kCooperative) {
  SwarmRunOptions o;
  o.agent.broadcast = src;
  o.params.tdoa_sigma_m = 0.09;
  o.params.output_bias_sigma_m = 0.0;
  o.agent.range.fusion = fusion;
  o.agent.range.sigma_m = 0.1;
  o.belief_latency_s = 0.01;
  return o;
}

TEST(SwarmLocalization, ExtrinsicBeliefsAreConsistentAndHelpOccludedAgents) {
  // GIVEN a 6-agent occluded swarm (agents 1, 3, 5 hear only anchors 0–2 for most of the flight), white TDoA noise
  const sim::SwarmScenario sc = sim::makeSwarmScenario("occluded", 6, 30.0);
  const sim::SwarmSimResult s = sim::simulateSwarm(sc, whiteNoiseSim(), 7);
  // WHEN every agent broadcasts its anchors-only belief and fuses its neighbours' (G21: nothing double counted)
  const SwarmScore score = runSwarmInProcess(sc, s, matchedFilter(NeighbourFusion::kNaive, BeliefSource::kIndependent));
  for (int k = 0; k < 6; ++k) {
    const SwarmScore::Row r = score.agent(k);
    std::printf("agent %d: n=%zu  RMSE coop %.3f indep %.3f m;  NEES coop %.2f indep %.2f\n", k, r.n, r.rmse_coop_m,
                r.rmse_indep_m, r.nees_coop, r.nees_indep);
    // THEN an occluded agent is localized far better with its neighbours than alone
    if (k % 2 == 1) {
      EXPECT_LT(r.rmse_coop_m, 0.3 * r.rmse_indep_m) << "agent " << k;
    }
  }
  // AND the cooperative estimate is consistent: mean position NEES ≈ 3 (χ²₃), within the factor-2.5 band of
  // NeesConsistencyTest (correlated samples, one per 0.1 s)
  const SwarmScore::Row all = score.overall();
  ASSERT_GT(all.n, 1000u);
  EXPECT_GT(all.nees_coop, 3.0 / 2.5);
  EXPECT_LT(all.nees_coop, 3.0 * 2.5);
}

TEST(SwarmLocalization, OccludedAgentsOfTheFullErrorModelStayConsistentAndNoneRunsAway) {
  // GIVEN the 20-agent occluded swarm of `uwbtdoa swarm` (agents 1, 3, … hear only anchors 0–2 for most of the
  // flight) with the simulator's full TDoA error model (bias, outliers, bursts) and the filter's defaults
  const sim::SwarmScenario sc = sim::makeSwarmScenario("occluded", 20, 30.0);
  const sim::SwarmSimResult s = sim::simulateSwarm(sc, sim::SimParams{}, 1);
  for (const double latency_s : {0.0, 0.005}) {
    SCOPED_TRACE("belief latency " + std::to_string(latency_s) + " s");
    SwarmRunOptions o;
    o.agent.broadcast = BeliefSource::kIndependent;
    o.agent.range.fusion = NeighbourFusion::kNaive;
    o.belief_latency_s = latency_s;
    // WHEN the agents exchange their anchors-only beliefs (the default, extrinsic fusion)
    const SwarmScore score = runSwarmInProcess(sc, s, o);
    // THEN no cooperative estimate runs away: a burst of garbage TDoA on the two pairs an occluded agent still hears
    // does not start a re-acquisition that three anchors cannot finish (filter.md F16k); before, one agent ran
    // 10–150 m off depending on the latency
    for (int k = 0; k < 20; ++k) EXPECT_LT(score.agent(k).rmse_coop_m, 0.8) << "agent " << k;
    // AND the anchors-only beliefs are consistent: a height lost below the floor is truncated to the floor's
    // moments (filter.md F22), not pinned there with the σ of a measurement (mean NEES 22 before)
    const SwarmScore::Row all = score.overall();
    EXPECT_LT(all.nees_indep, 3.0 * 2.5);
    EXPECT_GT(all.nees_coop, 3.0 / 2.5);
    EXPECT_LT(all.nees_coop, 3.0 * 2.5);
    EXPECT_LT(all.rmse_coop_m, 0.3);
    EXPECT_LT(all.rmse_coop_m, 0.25 * all.rmse_indep_m);
  }
}

TEST(SwarmLocalization, CovarianceIntersectionOfCooperativeBeliefsKeepsOccludedAgentsBounded) {
  // GIVEN the 20-agent occluded swarm with the full TDoA error model, the agents broadcasting their cooperative
  // beliefs (which carry what their neighbours gave them) and fusing them by covariance intersection (`--fusion ci`)
  const sim::SwarmScenario sc = sim::makeSwarmScenario("occluded", 20, 30.0);
  const sim::SwarmSimResult s = sim::simulateSwarm(sc, sim::SimParams{}, 1);
  SwarmRunOptions o;
  o.agent.broadcast = BeliefSource::kCooperative;
  o.agent.range.fusion = NeighbourFusion::kCovarianceIntersection;
  o.belief_latency_s = 0.01;
  // WHEN they run
  const SwarmScore score = runSwarmInProcess(sc, s, o);
  // THEN every cooperative estimate stays bounded and consistent: the intersection inflates the prior along the
  // position only (G21); scaling the whole covariance by 1/ω at every range inflated the attitude and IMU-bias
  // states without bound (overall cooperative RMSE 2·10¹⁶ m, negative NEES)
  for (int k = 0; k < 20; ++k) {
    EXPECT_LT(score.agent(k).rmse_coop_m, 0.8) << "agent " << k;
    EXPECT_GT(score.agent(k).nees_coop, 0.0) << "agent " << k;
  }
  const SwarmScore::Row all = score.overall();
  EXPECT_LT(all.nees_coop, 3.0 * 2.5);
  EXPECT_LT(all.rmse_coop_m, 0.5 * all.rmse_indep_m);  // the occluded agents gain from their neighbours
}

}  // namespace
}  // namespace uwb
