/** @file Swarm.cpp
 *  @brief Several agents in one arena: scenarios (S21), inter-agent two-way ranges (S22), occlusions (S23).
 *         docs/math/simulation.md.
 */
#include "uwb/sim/Swarm.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "uwb/core/Strings.h"
#include "uwb/model/TdoaModel.h"
#include "uwb/sim/Kinematics.h"

namespace uwb::sim {
namespace {

/// Fractional part of k·φ (golden ratio): well-spread per-agent values in [0, 1) (S21).
double spread(int k, double phi) { return std::fmod(static_cast<double>(k) * phi, 1.0); }

/// Ground, take-off and landing times for a flight of duration_s (S21): the `simulate` defaults shortened for short
/// runs so that at least half of the flight is the pattern.
void setPhases(TrajectoryParams& p, double duration_s) {
  // the climb to the highest agent (2.1 m) braked by the smoothstep (S2, |σ''| ≤ 7.51) keeps a positive thrust (S8)
  // when it takes at least 1.4 s
  constexpr double kMinClimb_s = 1.4;
  const double s = std::min(1.0, duration_s / 20.0);
  p.duration_s = duration_s;
  p.ground_before_s = 1.0 * s;
  p.ground_after_s = 0.5 * s;
  p.takeoff_s = std::max(2.0 * s, kMinClimb_s);
  p.landing_s = std::max(1.5 * s, kMinClimb_s);
  p.speed_ramp_s = 0.25 * p.patternDuration_s();
  p.speed_ramp_s = std::min(p.speed_ramp_s, 2.0);
}

}  // namespace

void TwrParams::validate() const {
  const auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("TwrParams: ") + what);
  };
  require(std::isfinite(rate_hz) && rate_hz > 0.0 && rate_hz <= 1000.0, "rate_hz must be in (0, 1000]");
  require(std::isfinite(noise_std_m) && noise_std_m >= 0.0, "noise_std_m must be >= 0");
  require(std::isfinite(radio_range_m) && radio_range_m > 0.0, "radio_range_m must be positive");
  require(max_partners >= 1, "max_partners must be >= 1");
  require(jitter_fraction >= 0.0 && jitter_fraction < 1.0, "jitter_fraction must be in [0, 1)");
}

std::vector<std::string> swarmScenarioNames() { return {"nominal", "few-anchors", "outside-hull", "occluded"}; }

SwarmScenario makeSwarmScenario(const std::string& name, int n_agents, double duration_s) {
  const std::vector<std::string> names = swarmScenarioNames();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string known;
    for (const std::string& n : names) appendToList(&known, n);
    throw std::invalid_argument("unknown swarm scenario '" + name + "' (expected one of: " + known + ")");
  }
  if (n_agents < 1 || n_agents > 200) throw std::invalid_argument("swarm: the number of agents must be in [1, 200]");
  if (!(std::isfinite(duration_s) && duration_s >= 4.0))
    throw std::invalid_argument("swarm: the duration must be at least 4 s");
  SwarmScenario sc;
  sc.name = name;
  sc.survey = paperAnchors();
  if (name == "few-anchors") {
    sc.survey.anchors.resize(4);  // ids 0–3: alternately low and high, a tetrahedron (S21)
    sc.survey.source = "preset:paper (anchors 0-3)";
  }
  // (S21) grid of cells over the room less a margin; one circle per cell
  const AnchorSurvey& all = paperAnchors();
  Vec3 lo = all.anchors.front().w_p, hi = lo;
  for (const Anchor& a : all.anchors) {
    lo = lo.cwiseMin(a.w_p);
    hi = hi.cwiseMax(a.w_p);
  }
  constexpr double kMargin_m = 0.8;
  const double w = hi.x() - lo.x() - 2.0 * kMargin_m, h = hi.y() - lo.y() - 2.0 * kMargin_m;
  const int cols = std::max(1, static_cast<int>(std::ceil(std::sqrt(n_agents * w / h))));
  const int rows = (n_agents + cols - 1) / cols;
  const double cw = w / cols, ch = h / rows;
  const double radius = std::clamp(0.3 * std::min(cw, ch), 0.15, 1.0);
  for (int k = 0; k < n_agents; ++k) {
    SwarmAgentSpec spec;
    TrajectoryParams& p = spec.trajectory;
    p.shape = TrajectoryShape::kCircle;
    setPhases(p, duration_s);
    const int r = k / cols, c = k % cols;
    p.w_center_xy = Vec2(lo.x() + kMargin_m + (c + 0.5) * cw, lo.y() + kMargin_m + (r + 0.5) * ch);
    p.radius_m = radius * (0.8 + 0.2 * spread(k, 0.381966));
    p.height_m = 0.9 + 1.2 * spread(k, 0.618034);
    const double speed_mps = 0.4 + 0.4 * spread(k, 0.7548777);
    p.omega_rps = std::min(speed_mps / p.radius_m, 1.5);
    p.yaw_mode = YawMode::kConstantRate;
    p.yaw0_rad = 2.0 * kPi * spread(k, 0.5698403);
    p.yaw_rate_rps = 0.3;
    if (name == "outside-hull" && k % 3 == 2) {
      // beyond the x walls of the hull by 0.45–0.95 m (the estimator's start-up accepts a fix up to 1 m outside the
      // anchors' box, F16)
      const double side = (k / 3) % 2 == 0 ? 1.0 : -1.0;
      p.w_center_xy.x() = side > 0 ? hi.x() + 0.7 : lo.x() - 0.7;
      p.radius_m = std::min(p.radius_m, 0.25);
      p.omega_rps = std::min(speed_mps / p.radius_m, 1.5);
    }
    if (name == "occluded" && k % 2 == 1) {
      // (S23) anchors 3–7 hidden from 2 s after take-off until 2 s before landing
      const double t0 = p.ground_before_s + p.takeoff_s + 2.0;
      const double t1 = p.duration_s - p.ground_after_s - p.landing_s - 2.0;
      if (t1 > t0) spec.occlusions.push_back({t0, t1, {3, 4, 5, 6, 7}});
    }
    sc.agents.push_back(std::move(spec));
  }
  return sc;
}

namespace {

// (S23) occlusion: a TDoA involving a hidden anchor is not received
void dropOccluded(const std::vector<Occlusion>& occlusions, SimResult& r) {
  if (occlusions.empty()) return;
  std::vector<TdoaMeasurement> kept;
  std::vector<TdoaTruth> kept_truth;
  for (std::size_t i = 0; i < r.flight.tdoa.size(); ++i) {
    const TdoaMeasurement& z = r.flight.tdoa[i];
    bool hidden = false;
    for (const Occlusion& o : occlusions) {
      if (z.t_s < o.t0_s || z.t_s > o.t1_s) continue;
      for (int id : o.hidden_anchor_ids) hidden = hidden || id == z.id_a || id == z.id_b;
    }
    if (hidden) continue;
    kept.push_back(z);
    kept_truth.push_back(r.tdoa_truth[i]);
  }
  r.flight.tdoa = std::move(kept);
  r.tdoa_truth = std::move(kept_truth);
}

/// (S22) One round's pairs: each agent picks its max_partners nearest agents within radio range; chosen[i·n + j]
/// (i < j) marks a pair. by_distance is scratch space.
void chooseTwrPairs(const std::vector<Vec3>& p, const TwrParams& tw, std::vector<char>& chosen,
                    std::vector<std::pair<double, int>>& by_distance) {
  const int n = static_cast<int>(p.size());
  std::fill(chosen.begin(), chosen.end(), 0);
  for (int i = 0; i < n; ++i) {
    by_distance.clear();
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      const double d = (p[static_cast<std::size_t>(i)] - p[static_cast<std::size_t>(j)]).norm();
      if (d <= tw.radio_range_m) by_distance.push_back({d, j});
    }
    const std::size_t m = std::min<std::size_t>(by_distance.size(), static_cast<std::size_t>(tw.max_partners));
    std::partial_sort(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(m), by_distance.end());
    for (std::size_t q = 0; q < m; ++q) {
      const int j = by_distance[q].second;
      chosen[static_cast<std::size_t>(std::min(i, j) * n + std::max(i, j))] = 1;
    }
  }
}

// (S22) TWR rounds at twr.rate_hz: each agent picks its max_partners nearest agents within radio range; every
// chosen pair ranges once per round at a jittered stamp, |p_tag,i − p_tag,j| + white noise, delivered to both.
std::vector<TwrObservation> simulateTwr(const std::vector<Trajectory>& traj, const TwrParams& tw,
                                        const SimParams& params, std::uint64_t seed) {
  const int n = static_cast<int>(traj.size());
  std::vector<TwrObservation> twr;
  std::seed_seq seq{static_cast<std::uint32_t>(seed & 0xffffffffu), static_cast<std::uint32_t>(seed >> 32),
                    0x74777221u /* "twr!" */};
  std::mt19937_64 rng(seq);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> jitter(0.0, tw.jitter_fraction);
  double duration = 0.0;
  for (const Trajectory& t : traj) duration = std::max(duration, t.duration_s());
  const double dt = 1.0 / tw.rate_hz;
  std::vector<Vec3> p(static_cast<std::size_t>(n));
  std::vector<char> chosen(static_cast<std::size_t>(n * n));
  std::vector<std::pair<double, int>> by_distance;
  const auto tagAt = [&](int k, double t) {
    const KinematicState s = kinematicState(traj[static_cast<std::size_t>(k)], t, params.rotor_drag_per_s);
    return tagPosition(s.w_p, s.w_q_b, params.b_t_tag);
  };
  for (long round = 0;; ++round) {
    const double t_round = static_cast<double>(round) * dt;
    if (t_round > duration) break;
    for (int k = 0; k < n; ++k) p[static_cast<std::size_t>(k)] = tagAt(k, t_round);
    chooseTwrPairs(p, tw, chosen, by_distance);
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        if (!chosen[static_cast<std::size_t>(i * n + j)]) continue;
        const double t = t_round + jitter(rng) * dt;
        if (t > duration) continue;
        const double d_true = range(tagAt(i, t), tagAt(j, t));  // (S22) model range (M3)
        twr.push_back({t, i, j, d_true + tw.noise_std_m * noise(rng), d_true});
      }
    }
  }
  std::stable_sort(twr.begin(), twr.end(),
                   [](const TwrObservation& a, const TwrObservation& b) { return a.t_s < b.t_s; });
  return twr;
}

}  // namespace

SwarmSimResult simulateSwarm(const SwarmScenario& scenario, const SimParams& params, std::uint64_t seed) {
  scenario.twr.validate();
  if (scenario.agents.empty()) throw std::invalid_argument("simulateSwarm: no agents");
  SwarmSimResult out;
  const int n = static_cast<int>(scenario.agents.size());
  std::vector<Trajectory> traj;
  traj.reserve(scenario.agents.size());
  for (int k = 0; k < n; ++k) {
    const SwarmAgentSpec& spec = scenario.agents[static_cast<std::size_t>(k)];
    SimResult r = simulateFlight(Scenario{scenario.survey, spec.trajectory}, params, seed * 1000u + static_cast<unsigned>(k));
    dropOccluded(spec.occlusions, r);
    if (k == 0) out.survey = r.survey;
    out.agents.push_back(std::move(r));
    traj.emplace_back(spec.trajectory);
  }
  out.twr = simulateTwr(traj, scenario.twr, params, seed);
  return out;
}

}  // namespace uwb::sim
