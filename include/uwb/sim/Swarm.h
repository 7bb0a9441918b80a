/** @file Swarm.h
 *  @brief N agents flying in one arena with the same anchors: each agent's own trajectory, IMU and anchor TDoA
 *         stream (simulateFlight), and two-way ranges (TWR) between neighbouring agents (docs/math/simulation.md
 *         S21–S23).
 *
 *  Scenarios (swarmScenarioNames()):
 *  - `nominal`: the 8 `paper` anchors, every agent inside their hull;
 *  - `few-anchors`: only anchors 0–3 of the `paper` room (one low/high tetrahedron, 3 independent TDoA);
 *  - `outside-hull`: every third agent circles 0.45–0.95 m outside the anchors' hull (beyond the x
 *    walls);
 *  - `occluded`: every second agent sees only anchors 0–2 (two TDoA pairs) from 2 s after take-off until 2 s
 *    before landing, so one direction of its position is unobservable from anchors alone.
 *  Deterministic by seed: agent k's flight uses seed·1000 + k, the TWR noise and schedule their own stream.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "uwb/sim/FlightSimulator.h"

namespace uwb::sim {

/// Anchors an agent does not hear during [t0_s, t1_s] (TDoA involving one of them are removed).
struct Occlusion {
  double t0_s = 0.0;
  double t1_s = 0.0;
  std::vector<int> hidden_anchor_ids;
};

struct SwarmAgentSpec {
  TrajectoryParams trajectory;
  std::vector<Occlusion> occlusions;
};

/// Inter-agent ranging (S22).
struct TwrParams {
  double rate_hz = 10.0;          ///< per pair
  double noise_std_m = 0.1;       ///< white range noise
  double radio_range_m = 3.0;     ///< pairs farther apart than this do not range
  int max_partners = 4;           ///< each agent ranges with at most this many nearest neighbours per round
  double jitter_fraction = 0.2;   ///< each pair's stamp within a round: round start + U(0, j) / rate
  void validate() const;
};

struct SwarmScenario {
  std::string name;
  AnchorSurvey survey;
  std::vector<SwarmAgentSpec> agents;
  TwrParams twr;
};

/// "nominal", "few-anchors", "outside-hull", "occluded".
std::vector<std::string> swarmScenarioNames();

/// Builds scenario `name` for n_agents ≥ 1 flying duration_s ≥ 4 s (S21): agents on a grid of cells over the room,
/// one circle per cell with its own radius, rate and height (non-colliding: circles stay inside their cells).
/// Throws std::invalid_argument for an unknown name or bad counts.
SwarmScenario makeSwarmScenario(const std::string& name, int n_agents, double duration_s);

/// One two-way range between agents i < j at t_s, delivered to both (S22).
struct TwrObservation {
  double t_s = 0.0;
  int agent_i = 0;
  int agent_j = 0;
  double range_m = 0.0;       ///< measured
  double range_true_m = 0.0;  ///< |p_tag,i − p_tag,j| at the exact poses
};

struct SwarmSimResult {
  AnchorSurvey survey;
  std::vector<SimResult> agents;   ///< per agent: flight (TDoA after occlusion), truth
  std::vector<TwrObservation> twr; ///< time-ordered
};

/// Simulates every agent (simulateFlight with `params`) and the inter-agent ranges (S22, S23).
SwarmSimResult simulateSwarm(const SwarmScenario& scenario, const SimParams& params, std::uint64_t seed);

}  // namespace uwb::sim
