/** @file SwarmLocalization.h
 *  @brief Cooperative localization of several agents: one agent's pair of estimators (cooperative: anchors, IMU and
 *         ranges to neighbours whose broadcast beliefs it fuses, docs/math/message-passing.md G20–G22; independent:
 *         the same agent without the ranges), its broadcast belief, the scoring against the simulated truth, and an
 *         in-process run of a whole simulated swarm (what `uwbtdoa swarm` does over ZeroMQ, without the processes).
 *
 *  @code
 *    CooperativeAgent agent(k, params, anchors, coop);
 *    agent.addImu(t, imu); agent.addTdoa(z);                       // both estimators
 *    agent.addBelief(belief_of_j);                                  // from the network
 *    agent.addRange(t, j, range_m);                                 // cooperative estimator only
 *    if (agent.beliefDue()) publish(agent.belief());
 *  @endcode
 */
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "uwb/filter/Estimator.h"
#include "uwb/sim/Swarm.h"

namespace uwb {

/// What an agent broadcasts (message-passing.md G22): its tag-position belief and its velocity, stamped.
struct NeighbourBelief {
  int agent = -1;
  double t_s = 0.0;
  Moments3 tag{Vec3::Zero(), Mat3::Zero()};
  Vec3 w_v = Vec3::Zero();
  Mat3 cov_v = Mat3::Zero();
};

/// Which estimate an agent broadcasts (message-passing.md G21).
enum class BeliefSource : unsigned char {
  kCooperative,  ///< the cooperative estimator's: carries what the agent learned from its neighbours (loops)
  kIndependent,  ///< the anchors-and-IMU-only estimator's: contains nothing any other agent contributed
};

struct CooperativeAgentOptions {
  CooperativeRangeOptions range;
  BeliefSource broadcast = BeliefSource::kIndependent;
  double belief_period_s = 0.1;   ///< broadcast at most this often (sensor time)
  double max_belief_age_s = 0.5;  ///< a neighbour's belief older than this is not used
  double a_max_mps2 = 3.0;        ///< unmodelled acceleration bound when ageing a belief (G22)
};

class CooperativeAgent {
 public:
  CooperativeAgent(int id, const EkfParams& params, const AnchorTable& anchors, const CooperativeAgentOptions& options);

  void addImu(double t_s, const ImuReading& imu);
  void addTdoa(const TdoaMeasurement& z);
  /// Keeps the newest belief of each other agent (own and older ones ignored).
  void addBelief(const NeighbourBelief& belief);
  /// A TWR to agent `peer`: applied to the cooperative estimator with the peer's latest belief aged to t_s (G22);
  /// counted as missing when there is none within max_belief_age_s.
  void addRange(double t_s, int peer, double range_m);
  /// True (once per period) when a broadcast is due at the current sensor time and the position is known.
  bool beliefDue();
  /// The broadcast belief (tagBelief of the estimate options.broadcast names).
  NeighbourBelief belief() const;

  int id() const { return id_; }
  const Estimator& cooperative() const { return *coop_; }
  const Estimator& independent() const { return *indep_; }
  std::size_t rangesWithoutBelief() const { return n_no_belief_; }

 private:
  int id_;
  CooperativeAgentOptions options_;
  Vec3 b_t_tag_;
  std::unique_ptr<Estimator> coop_, indep_;
  std::vector<NeighbourBelief> latest_;
  double t_last_belief_ = -1e300;
  std::size_t n_no_belief_ = 0;
};

/// Position errors and NEES of the two estimators of every agent against the truth (the body origin).
class SwarmScore {
 public:
  explicit SwarmScore(int n_agents);
  /// One sample: agent k's cooperative and independent estimates at t against the true body position.
  void add(int agent, const Vec3& truth, const Vec3& p_coop, const Mat3& cov_coop, const Vec3& p_indep,
           const Mat3& cov_indep);
  /// Scores over n samples; with n = 0 every score is NaN (no sample, no score).
  struct Row {
    std::size_t n = 0;
    double rmse_coop_m = 0.0, rmse_indep_m = 0.0;  ///< 3-D position RMSE
    double nees_coop = 0.0, nees_indep = 0.0;      ///< mean position NEES (3 dof; ideal 3)
  };
  Row agent(int k) const;
  Row overall() const;
  int agents() const { return static_cast<int>(acc_.size()); }

 private:
  struct Acc {
    std::size_t n = 0;
    double se_coop = 0.0, se_indep = 0.0, nees_coop = 0.0, nees_indep = 0.0;
  };
  static Row toRow(const Acc& a);
  std::vector<Acc> acc_;
};

/// True body position of agent k at t (exact kinematics of its trajectory, S1–S8).
Vec3 swarmTruthPosition(const sim::SwarmScenario& scenario, int agent, double t_s);
/// Samples are scored while the agent flies its pattern (after take-off + settle_s, before landing).
bool swarmScoringWindow(const sim::SwarmScenario& scenario, int agent, double t_s, double settle_s = 2.0);

struct SwarmRunOptions {
  EkfParams params;
  CooperativeAgentOptions agent;
  double score_period_s = 0.1;   ///< one scored sample per agent this often
  double belief_latency_s = 0.0; ///< a broadcast reaches the others this long after it was made (sensor time)
};

/// Every agent's events merged in time order and fed to its CooperativeAgent; beliefs delivered to all others
/// after belief_latency_s. Deterministic. (The same per-agent logic as `uwbtdoa swarm`, without ZeroMQ.)
SwarmScore runSwarmInProcess(const sim::SwarmScenario& scenario, const sim::SwarmSimResult& sim,
                             const SwarmRunOptions& options);

}  // namespace uwb
