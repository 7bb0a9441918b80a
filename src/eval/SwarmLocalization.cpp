/** @file SwarmLocalization.cpp
 *  @brief Cooperative agents (docs/math/message-passing.md G20–G22), scoring and the in-process swarm run.
 */
#include "uwb/eval/SwarmLocalization.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>

#include "uwb/eval/Localization.h"
#include "uwb/sim/Kinematics.h"

namespace uwb {

CooperativeAgent::CooperativeAgent(int id, const EkfParams& params, const AnchorTable& anchors,
                                   const CooperativeAgentOptions& options)
    : id_(id),
      options_(options),
      b_t_tag_(params.b_t_tag),
      coop_(std::make_unique<Estimator>(params, anchors)),
      indep_(std::make_unique<Estimator>(params, anchors)) {
  options_.range.b_t_tag = params.b_t_tag;
}

void CooperativeAgent::addImu(double t_s, const ImuReading& imu) {
  coop_->addImu(t_s, imu);
  indep_->addImu(t_s, imu);
}

void CooperativeAgent::addTdoa(const TdoaMeasurement& z) {
  coop_->addTdoa(z);
  indep_->addTdoa(z);
}

void CooperativeAgent::addBelief(const NeighbourBelief& belief) {
  if (belief.agent < 0 || belief.agent == id_) return;
  if (latest_.size() <= static_cast<std::size_t>(belief.agent)) latest_.resize(static_cast<std::size_t>(belief.agent) + 1);
  NeighbourBelief& slot = latest_[static_cast<std::size_t>(belief.agent)];
  if (slot.agent < 0 || belief.t_s >= slot.t_s) slot = belief;
}

void CooperativeAgent::addRange(double t_s, int peer, double range_m) {
  if (peer < 0 || static_cast<std::size_t>(peer) >= latest_.size() || latest_[static_cast<std::size_t>(peer)].agent < 0 ||
      std::abs(t_s - latest_[static_cast<std::size_t>(peer)].t_s) > options_.max_belief_age_s) {
    ++n_no_belief_;
    return;
  }
  const NeighbourBelief& b = latest_[static_cast<std::size_t>(peer)];
  const Moments3 aged = ageBelief(b.tag, b.w_v, b.cov_v, t_s - b.t_s, options_.a_max_mps2);  // (G22)
  coop_->addNeighbourRange(t_s, aged, range_m, options_.range);
}

bool CooperativeAgent::beliefDue() {
  if (!coop_->ready() || !indep_->ready()) return false;
  const double t = coop_->time();
  if (t - t_last_belief_ < options_.belief_period_s && t >= t_last_belief_) return false;
  t_last_belief_ = t;
  return true;
}

NeighbourBelief CooperativeAgent::belief() const {
  const Estimator& src = options_.broadcast == BeliefSource::kIndependent ? *indep_ : *coop_;
  const LocalizerEstimate e = src.estimate();
  NeighbourBelief b;
  b.agent = id_;
  b.t_s = e.t_s;
  b.tag = tagBelief(e.x, e.cov_pose, b_t_tag_);
  b.w_v = e.x.w_v_b;
  b.cov_v = src.covariance().block<3, 3>(kVel, kVel);
  return b;
}

SwarmScore::SwarmScore(int n_agents) : acc_(static_cast<std::size_t>(std::max(n_agents, 0))) {}

void SwarmScore::add(int agent, const Vec3& truth, const Vec3& p_coop, const Mat3& cov_coop, const Vec3& p_indep,
                     const Mat3& cov_indep) {
  if (agent < 0 || agent >= agents()) throw std::invalid_argument("SwarmScore: agent index out of range");
  Acc& a = acc_[static_cast<std::size_t>(agent)];
  const Vec3 ec = p_coop - truth, ei = p_indep - truth;
  ++a.n;
  a.se_coop += ec.squaredNorm();
  a.se_indep += ei.squaredNorm();
  // position NEES eᵀ Σ⁻¹ e (3 dof)
  a.nees_coop += ec.dot(cov_coop.ldlt().solve(ec));
  a.nees_indep += ei.dot(cov_indep.ldlt().solve(ei));
}

SwarmScore::Row SwarmScore::toRow(const Acc& a) {
  Row r;
  r.n = a.n;
  if (a.n == 0) {
    // no sample, no score: NaN, never a 0.000 that reads as perfect
    r.rmse_coop_m = r.rmse_indep_m = r.nees_coop = r.nees_indep = std::numeric_limits<double>::quiet_NaN();
    return r;
  }
  const double n = static_cast<double>(a.n);
  r.rmse_coop_m = std::sqrt(a.se_coop / n);
  r.rmse_indep_m = std::sqrt(a.se_indep / n);
  r.nees_coop = a.nees_coop / n;
  r.nees_indep = a.nees_indep / n;
  return r;
}

SwarmScore::Row SwarmScore::agent(int k) const { return toRow(acc_.at(static_cast<std::size_t>(k))); }

SwarmScore::Row SwarmScore::overall() const {
  Acc all;
  for (const Acc& a : acc_) {
    all.n += a.n;
    all.se_coop += a.se_coop;
    all.se_indep += a.se_indep;
    all.nees_coop += a.nees_coop;
    all.nees_indep += a.nees_indep;
  }
  return toRow(all);
}

Vec3 swarmTruthPosition(const sim::SwarmScenario& scenario, int agent, double t_s) {
  const sim::Trajectory traj(scenario.agents.at(static_cast<std::size_t>(agent)).trajectory);
  return traj.evaluate(t_s).w_p;
}

bool swarmScoringWindow(const sim::SwarmScenario& scenario, int agent, double t_s, double settle_s) {
  const sim::TrajectoryParams& p = scenario.agents.at(static_cast<std::size_t>(agent)).trajectory;
  return t_s >= p.ground_before_s + p.takeoff_s + settle_s && t_s <= p.duration_s - p.ground_after_s - p.landing_s;
}

SwarmScore runSwarmInProcess(const sim::SwarmScenario& scenario, const sim::SwarmSimResult& sim,
                             const SwarmRunOptions& options) {
  const int n = static_cast<int>(sim.agents.size());
  if (n != static_cast<int>(scenario.agents.size()))
    throw std::invalid_argument("runSwarmInProcess: the simulation and the scenario differ in the number of agents");
  const AnchorTable anchors = anchorTableFromSurvey(sim.survey, options.params.anchor_sigma_m);
  std::vector<SensorLog> logs;
  std::vector<std::unique_ptr<CooperativeAgent>> agents;
  std::vector<sim::Trajectory> truth;
  for (int k = 0; k < n; ++k) {
    logs.push_back(sensorLogFromFlight(sim.agents[static_cast<std::size_t>(k)].flight));
    agents.push_back(std::make_unique<CooperativeAgent>(k, options.params, anchors, options.agent));
    truth.emplace_back(scenario.agents[static_cast<std::size_t>(k)].trajectory);
  }
  // one time-ordered sequence over all agents: (t, agent, kind, index); kind 0 IMU, 1 TDoA, 2 TWR (index into twr)
  struct Ev {
    double t;
    int agent;
    int kind;
    std::size_t index;
  };
  std::vector<Ev> events;
  for (int k = 0; k < n; ++k) {
    SensorEventCursor cursor(logs[static_cast<std::size_t>(k)]);
    for (SensorEvent ev; cursor.next(ev);) {
      if (ev.kind == SensorEvent::Kind::kTof) continue;
      events.push_back({ev.t_s, k, ev.kind == SensorEvent::Kind::kImu ? 0 : 1, ev.index});
    }
  }
  for (std::size_t i = 0; i < sim.twr.size(); ++i) {
    events.push_back({sim.twr[i].t_s, sim.twr[i].agent_i, 2, i});
    events.push_back({sim.twr[i].t_s, sim.twr[i].agent_j, 2, i});
  }
  std::stable_sort(events.begin(), events.end(), [](const Ev& a, const Ev& b) {
    return a.t < b.t || (a.t == b.t && a.kind < b.kind);
  });
  SwarmScore score(n);
  std::vector<double> next_score(static_cast<std::size_t>(n), 0.0);
  std::deque<std::pair<double, NeighbourBelief>> in_flight;  // delivery time, belief
  for (const Ev& ev : events) {
    while (!in_flight.empty() && in_flight.front().first <= ev.t) {
      for (auto& a : agents) a->addBelief(in_flight.front().second);
      in_flight.pop_front();
    }
    CooperativeAgent& a = *agents[static_cast<std::size_t>(ev.agent)];
    const SensorLog& log = logs[static_cast<std::size_t>(ev.agent)];
    if (ev.kind == 0) {
      a.addImu(log.imu[ev.index].t_s, log.imu[ev.index].imu);
    } else if (ev.kind == 1) {
      a.addTdoa(log.tdoa[ev.index]);
    } else {
      const sim::TwrObservation& r = sim.twr[ev.index];
      a.addRange(r.t_s, r.agent_i == ev.agent ? r.agent_j : r.agent_i, r.range_m);
    }
    if (a.beliefDue()) in_flight.push_back({ev.t + options.belief_latency_s, a.belief()});
    double& ts = next_score[static_cast<std::size_t>(ev.agent)];
    if (ev.t >= ts) {
      ts = ev.t + options.score_period_s;
      if (a.cooperative().ready() && a.independent().ready() && swarmScoringWindow(scenario, ev.agent, ev.t)) {
        const LocalizerEstimate c = a.cooperative().estimate(), i = a.independent().estimate();
        score.add(ev.agent, truth[static_cast<std::size_t>(ev.agent)].evaluate(ev.t).w_p, c.x.w_p_b,
                  c.cov_pose.topLeftCorner<3, 3>(), i.x.w_p_b, i.cov_pose.topLeftCorner<3, 3>());
      }
    }
  }
  return score;
}

}  // namespace uwb
