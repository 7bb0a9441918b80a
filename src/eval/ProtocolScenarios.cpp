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
      const auto want = [&](const std::string& scenario) {
        return only.empty() || (scenario + "-" + tag).find(only) != std::string::npos;
      };
      // a flight whose log starts after_climb_s after the climb and ends 1 s before the landing
      const auto cutInAir = [&](const std::string& name, sim::TrajectoryShape shape, double duration_s,
                                double after_climb_s) {
        sim::Scenario sc = sim::makeScenario(layout.survey, shape, duration_s);
        const sim::SimResult r = sim::simulateFlight(sc, sp, seed);
        const sim::TrajectoryParams& tp = sc.trajectory;
        const double t0 = tp.ground_before_s + tp.takeoff_s + after_climb_s;
        const double t1 = tp.duration_s - tp.ground_after_s - tp.landing_s - 1.0;
        out.push_back(
            {name + "-" + tag, name, "cut in the air", sliceFlight(r.flight, t0, t1), r.survey, true, r.flight});
      };
      // start in hover: a circle with a vertical sine, the log cut 2 s after the climb
      if (want("hover-start")) cutInAir("hover-start", sim::TrajectoryShape::kCircleSine, 60.0, 2.0);
      if (want("still-hover")) {
        // a still hover of 16 s between take-off and landing (must not read as landed)
        sim::Scenario sc = sim::makeScenario(layout.survey, sim::TrajectoryShape::kHover, 4.0 + 3.0 + 16.0 + 3.0 + 4.0);
        sc.trajectory.yaw_mode = sim::YawMode::kConstant;
        const sim::SimResult r = sim::simulateFlight(sc, sp, seed);
        out.push_back({"still-hover-" + tag, "still-hover", "full", r.flight, r.survey, false, {}});
      }
      if (want("two-takeoffs")) {
        // two take-offs: a circle, landing, then a hover flight from where it landed
        sim::Scenario a = sim::makeScenario(layout.survey, sim::TrajectoryShape::kCircle, 40.0);
        const sim::SimResult ra = sim::simulateFlight(a, sp, seed);
        sim::Scenario b = sim::makeScenario(layout.survey, sim::TrajectoryShape::kHover, 24.0);
        const PoseSample& last = ra.flight.pose.back();
        b.trajectory.w_center_xy = last.w_p_b.head<2>();
        b.trajectory.yaw_mode = sim::YawMode::kConstant;
        const Vec3 fwd = last.w_q_b * Vec3::UnitX();
        b.trajectory.yaw0_rad = std::atan2(fwd.y(), fwd.x());
        sim::SimResult rb = sim::simulateFlight(b, sp, seed);
        Flight f = ra.flight;
        shiftFlight(rb.flight, ra.flight.acc.back().t_s + 1e-3);
        append(f, rb.flight);
        out.push_back({"two-takeoffs-" + tag, "two-takeoffs", "full", f, ra.survey, false, {}});
      }
      if (want("fast")) {
        // fast: a circle at 2.25 m/s, yawing
        sim::Scenario sc = sim::makeScenario(layout.survey, sim::TrajectoryShape::kCircle, 40.0);
        sc.trajectory.omega_rps = 2.25 / sc.trajectory.radius_m;
        const sim::SimResult r = sim::simulateFlight(sc, sp, seed);
        out.push_back({"fast-" + tag, "fast", "full", r.flight, r.survey, false, {}});
      }
      if (want("tdoa3")) {
        // TDoA3 (S19b): random anchor pairs at 200 Hz instead of the neighbour round robin, a circle with a vertical
        // sine from the ground to the ground
        sim::SimParams sp3 = sp;
        sp3.tdoa.tdoa3 = true;
        sp3.tdoa.rate_hz = 200.0;
        const sim::SimResult r =
            sim::simulateFlight(sim::makeScenario(layout.survey, sim::TrajectoryShape::kCircleSine, 40.0), sp3, seed);
        out.push_back({"tdoa3-" + tag, "tdoa3", "full", r.flight, r.survey, false, {}});
      }
      // a yawing figure eight started in the air (unknown yaw at the log's start)
      if (want("yawing-start")) cutInAir("yawing-start", sim::TrajectoryShape::kFigureEight, 50.0, 6.0);
      if (want("hand-carried")) {
        // carried by a walking person: 1.1 m high, 1 m/s on a 2 m circle while turning, a 2 Hz, ±2 cm gait bob
        // (≈ 3 m/s² peak vertical acceleration); the log starts while walking at full speed
        sim::Scenario sc = sim::makeScenario(layout.survey, sim::TrajectoryShape::kCircleSine, 50.0);
        sim::TrajectoryParams& tp = sc.trajectory;
        tp.height_m = 1.1;
        tp.radius_m = 2.0;
        tp.omega_rps = 1.0 / tp.radius_m;
        tp.sine_amplitude_m = 0.02;
        tp.sine_omega_ratio = 2.0 * M_PI * 2.0 / tp.omega_rps;
        const sim::SimResult r = sim::simulateFlight(sc, sp, seed);
        const double t0 = tp.ground_before_s + tp.takeoff_s + tp.speed_ramp_s + 1.0;
        const double t1 = tp.duration_s - tp.ground_after_s - tp.landing_s - 1.0;
        out.push_back({"hand-carried-" + tag, "hand-carried", "cut in the air", sliceFlight(r.flight, t0, t1), r.survey,
                       true, r.flight});
      }
    }
  }
  return out;
}

}  // namespace uwb
