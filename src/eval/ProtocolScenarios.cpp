/** @file ProtocolScenarios.cpp
 *  @brief Simulated flights of the generalization protocol (docs/math/simulation.md S1–S20 for the simulator).
 */
#include "uwb/eval/ProtocolScenarios.h"

#include <cmath>
#include <filesystem>

#include "uwb/io/FlightWindow.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace uwb {
namespace {

/// Another room: the paper's anchors rotated by 30° about z and moved by (3, −2, 0) m.
AnchorSurvey movedPaperAnchors() {
  AnchorSurvey s = sim::paperAnchors();
  const Mat3 R = Eigen::AngleAxisd(30.0 * M_PI / 180.0, Vec3::UnitZ()).toRotationMatrix();
  for (Anchor& a : s.anchors) a.w_p = R * a.w_p + Vec3(3.0, -2.0, 0.0);
  return s;
}

void shiftFlight(Flight& f, double dt) {
  for (auto& s : f.tdoa) s.t_s += dt;
  for (auto& s : f.acc) s.t_s += dt;
  for (auto& s : f.gyro) s.t_s += dt;
  for (auto& s : f.pose) s.t_s += dt;
  for (auto& s : f.tof) s.t_s += dt;
}

void append(Flight& a, const Flight& b) {
  a.tdoa.insert(a.tdoa.end(), b.tdoa.begin(), b.tdoa.end());
  a.acc.insert(a.acc.end(), b.acc.begin(), b.acc.end());
  a.gyro.insert(a.gyro.end(), b.gyro.begin(), b.gyro.end());
  a.pose.insert(a.pose.end(), b.pose.begin(), b.pose.end());
  a.tof.insert(a.tof.end(), b.tof.begin(), b.tof.end());
}

sim::SimParams simParams(std::uint64_t field_seed) {
  sim::SimParams p;
  p.bias.field_seed = field_seed;
  return p;
}

/// One anchor layout and seed of the protocol; `tag` ("<layout>-s<seed>") ends every run's name.
struct ScenarioContext {
  const AnchorSurvey& survey;
  const sim::SimParams& sp;
  std::uint64_t seed;
  const std::string& tag;
};

/// A flight whose log starts after_climb_s after the climb and ends 1 s before the landing.
SimScenarioRun cutInAir(const ScenarioContext& c, const std::string& name, sim::TrajectoryShape shape,
                        double duration_s, double after_climb_s) {
  sim::Scenario sc = sim::makeScenario(c.survey, shape, duration_s);
  const sim::SimResult r = sim::simulateFlight(sc, c.sp, c.seed);
  const sim::TrajectoryParams& tp = sc.trajectory;
  const double t0 = tp.ground_before_s + tp.takeoff_s + after_climb_s;
  const double t1 = tp.duration_s - tp.ground_after_s - tp.landing_s - 1.0;
  return {name + "-" + c.tag, name, "cut in the air", sliceFlight(r.flight, t0, t1), r.survey, true, r.flight};
}

/// A still hover of 16 s between take-off and landing (must not read as landed).
SimScenarioRun stillHover(const ScenarioContext& c) {
  sim::Scenario sc = sim::makeScenario(c.survey, sim::TrajectoryShape::kHover, 4.0 + 3.0 + 16.0 + 3.0 + 4.0);
  sc.trajectory.yaw_mode = sim::YawMode::kConstant;
  const sim::SimResult r = sim::simulateFlight(sc, c.sp, c.seed);
  return {"still-hover-" + c.tag, "still-hover", "full", r.flight, r.survey, false, {}};
}

/// Two take-offs: a circle, landing, then a hover flight from where it landed.
SimScenarioRun twoTakeoffs(const ScenarioContext& c) {
  sim::Scenario a = sim::makeScenario(c.survey, sim::TrajectoryShape::kCircle, 40.0);
  const sim::SimResult ra = sim::simulateFlight(a, c.sp, c.seed);
  sim::Scenario b = sim::makeScenario(c.survey, sim::TrajectoryShape::kHover, 24.0);
  const PoseSample& last = ra.flight.pose.back();
  b.trajectory.w_center_xy = last.w_p_b.head<2>();
  b.trajectory.yaw_mode = sim::YawMode::kConstant;
  const Vec3 fwd = last.w_q_b * Vec3::UnitX();
  b.trajectory.yaw0_rad = std::atan2(fwd.y(), fwd.x());
  sim::SimResult rb = sim::simulateFlight(b, c.sp, c.seed);
  Flight f = ra.flight;
  shiftFlight(rb.flight, ra.flight.acc.back().t_s + 1e-3);
  append(f, rb.flight);
  return {"two-takeoffs-" + c.tag, "two-takeoffs", "full", f, ra.survey, false, {}};
}

/// Fast: a circle at 2.25 m/s, yawing.
SimScenarioRun fastCircle(const ScenarioContext& c) {
  sim::Scenario sc = sim::makeScenario(c.survey, sim::TrajectoryShape::kCircle, 40.0);
  sc.trajectory.omega_rps = 2.25 / sc.trajectory.radius_m;
  const sim::SimResult r = sim::simulateFlight(sc, c.sp, c.seed);
  return {"fast-" + c.tag, "fast", "full", r.flight, r.survey, false, {}};
}

/// TDoA3 (S19b): random anchor pairs at 200 Hz instead of the neighbour round robin, a circle with a vertical sine
/// from the ground to the ground.
SimScenarioRun tdoa3(const ScenarioContext& c) {
  sim::SimParams sp3 = c.sp;
  sp3.tdoa.tdoa3 = true;
  sp3.tdoa.rate_hz = 200.0;
  const sim::SimResult r =
      sim::simulateFlight(sim::makeScenario(c.survey, sim::TrajectoryShape::kCircleSine, 40.0), sp3, c.seed);
  return {"tdoa3-" + c.tag, "tdoa3", "full", r.flight, r.survey, false, {}};
}

/// Carried by a walking person: 1.1 m high, 1 m/s on a 2 m circle while turning, a 2 Hz, ±2 cm gait bob (≈ 3 m/s²
/// peak vertical acceleration); the log starts while walking at full speed.
SimScenarioRun handCarried(const ScenarioContext& c) {
  sim::Scenario sc = sim::makeScenario(c.survey, sim::TrajectoryShape::kCircleSine, 50.0);
  sim::TrajectoryParams& tp = sc.trajectory;
  tp.height_m = 1.1;
  tp.radius_m = 2.0;
  tp.omega_rps = 1.0 / tp.radius_m;
  tp.sine_amplitude_m = 0.02;
  tp.sine_omega_ratio = 2.0 * M_PI * 2.0 / tp.omega_rps;
  const sim::SimResult r = sim::simulateFlight(sc, c.sp, c.seed);
  const double t0 = tp.ground_before_s + tp.takeoff_s + tp.speed_ramp_s + 1.0;
  const double t1 = tp.duration_s - tp.ground_after_s - tp.landing_s - 1.0;
  return {"hand-carried-" + c.tag, "hand-carried", "cut in the air", sliceFlight(r.flight, t0, t1), r.survey,
          true, r.flight};
}

}  // namespace

std::vector<SimScenarioRun> protocolSimulations(const std::string& data_dir, const std::vector<std::uint64_t>& seeds,
                                                const std::string& only) {
  struct Layout {
    std::string name;
    AnchorSurvey survey;
  };
  std::vector<Layout> layouts = {{"paper", sim::paperAnchors()}, {"moved", movedPaperAnchors()}};
  try {
    layouts.push_back({"const4", sim::anchorPreset("util-const4", data_dir)});
  } catch (const std::exception&) {
    // the UTIL constellation needs the real-data folder; the two built-in layouts remain
  }
  std::vector<SimScenarioRun> out;
  for (const Layout& layout : layouts) {
    for (std::uint64_t seed : seeds) {
      const sim::SimParams sp = simParams(seed);
      const std::string tag = layout.name + "-s" + std::to_string(seed);
      const ScenarioContext c{layout.survey, sp, seed, tag};
      const auto want = [&](const std::string& scenario) {
        return only.empty() || (scenario + "-" + tag).find(only) != std::string::npos;
      };
      // start in hover: a circle with a vertical sine, the log cut 2 s after the climb
      if (want("hover-start")) out.push_back(cutInAir(c, "hover-start", sim::TrajectoryShape::kCircleSine, 60.0, 2.0));
      if (want("still-hover")) out.push_back(stillHover(c));
      if (want("two-takeoffs")) out.push_back(twoTakeoffs(c));
      if (want("fast")) out.push_back(fastCircle(c));
      if (want("tdoa3")) out.push_back(tdoa3(c));
      // a yawing figure eight started in the air (unknown yaw at the log's start)
      if (want("yawing-start")) out.push_back(cutInAir(c, "yawing-start", sim::TrajectoryShape::kFigureEight, 50.0, 6.0));
      if (want("hand-carried")) out.push_back(handCarried(c));
    }
  }
  return out;
}

}  // namespace uwb
