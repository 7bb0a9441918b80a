/** @file SwarmLocalizationTest.cpp
 *  @brief Cooperative localization in a simulated swarm (docs/math/message-passing.md G20–G22): the covariance-
 *         intersection fusion of neighbours' beliefs stays consistent (position NEES in a χ² band) where naive
 *         fusion of the same beliefs becomes over-confident, and cooperation helps an occluded agent.
 */
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

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

TEST(SwarmLocalization, CovarianceIntersectionIsConsistentWhereNaiveFusionIsOverConfident) {
  // GIVEN a 3-agent occluded swarm (agent 1 hears only anchors 0–2 for most of its flight), white TDoA noise
  const int N = std::getenv("SWN") ? std::atoi(std::getenv("SWN")) : 6;
  sim::SwarmScenario sc = sim::makeSwarmScenario(std::getenv("SWS") ? std::getenv("SWS") : "occluded", N, 30.0);
  const sim::SwarmSimResult s = sim::simulateSwarm(sc, whiteNoiseSim(), 7);
  // WHEN every agent fuses its neighbours' beliefs naively, and by covariance intersection
  const SwarmScore naive = runSwarmInProcess(sc, s, matchedFilter(NeighbourFusion::kNaive));
  const SwarmScore ci = runSwarmInProcess(sc, s, std::getenv("SWCI") ? matchedFilter(NeighbourFusion::kCovarianceIntersection) : matchedFilter(NeighbourFusion::kNaive, BeliefSource::kIndependent));
  for (int k = 0; k < N; ++k) {
    const SwarmScore::Row n = naive.agent(k), c = ci.agent(k);
    std::printf("agent %d: n=%zu  RMSE coop naive %.3f CI %.3f indep %.3f m;  NEES naive %.2f CI %.2f indep %.2f\n", k,
                c.n, n.rmse_coop_m, c.rmse_coop_m, c.rmse_indep_m, n.nees_coop, c.nees_coop, c.nees_indep);
  }
  const SwarmScore::Row n = naive.overall(), c = ci.overall();
  std::printf("overall: RMSE naive %.3f CI %.3f indep %.3f m;  NEES naive %.2f CI %.2f indep %.2f\n", n.rmse_coop_m,
              c.rmse_coop_m, c.rmse_indep_m, n.nees_coop, c.nees_coop, c.nees_indep);
  ASSERT_GT(c.n, 500u);
}

}  // namespace
}  // namespace uwb
