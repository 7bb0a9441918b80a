/** @file cmd_demo.cpp
 *  @brief `uwbtdoa demo`: the built-in default. The paper's experiment on simulated flights: 8 anchors in the
 *         corners of a room, a zigzag training flight and a circular test flight, the quadrotor yawing while it
 *         flies (paper III-C); trains the three kernels, localizes without/with correction, writes the report.
 */
#include <fmt/format.h>

#include <filesystem>
#include <iostream>

#include "Command.h"
#include "Report.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace uwb::app {
namespace {

struct Options {
  std::uint64_t seed = 1;
  double train_duration_s = 90.0;
  double test_duration_s = 60.0;
  int test_flights = 2;
  EvaluationCliOptions eval;
};

/// The demo's measurement errors: dominated by what the paper's GP inputs can explain (antenna pattern and
/// occlusion by the drone's body as functions of the body-frame anchor directions, paper III-B and Fig. 7), with
/// smaller unlearnable multipath and noise. The simulator's defaults, tuned to the real util-pilot flights, have a
/// much smaller learnable share (docs/math/simulation.md). All flights share one drone and one room (field_seed):
/// what the GP learns on the training flight is the same hardware the test flights carry.
sim::SimParams demoSimParams(std::uint64_t field_seed) {
  sim::SimParams p;
  p.bias.field_seed = field_seed;
  p.bias.antenna_rms_m = 0.15;
  p.bias.anchor_pattern_rms_m = 0.05;
  p.bias.nlos_bias_m = 0.25;
  p.bias.multipath_std_m = 0.04;
  p.bias.noise_std_m = 0.06;
  return p;
}

NamedFlight simulate(const std::string& name, sim::TrajectoryShape shape, double duration_s, std::uint64_t seed,
                     std::uint64_t field_seed, const std::string& dir) {
  sim::Scenario scenario = sim::makeScenario(sim::paperAnchors(), shape, duration_s);
  const sim::SimResult sim = sim::simulateFlight(scenario, demoSimParams(field_seed), seed);
  const std::string path = (std::filesystem::path(dir) / (name + ".csv")).string();
  writeFlightCsv(sim.flight, path);
  std::cerr << fmt::format("simulated {} ({:.0f} s, {} TDoA) → {}\n", name, duration_s, sim.flight.tdoa.size(), path);
  return {name, sim.flight};
}

void setup(CLI::App& sub) {
  auto opt = std::make_shared<Options>();
  opt->eval.out_dir = "demo-out";
  opt->eval.inducing = {10, 30, 50};
  opt->eval.repeats = 1;
  sub.add_option("--seed", opt->seed, "Simulation seed (the drone and room of all flights; each flight's noise)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub.add_option("--train-duration", opt->train_duration_s, "Zigzag training flight length [s]")->capture_default_str();
  sub.add_option("--test-duration", opt->test_duration_s, "Circular test flight length [s]")->capture_default_str();
  sub.add_option("--test-flights", opt->test_flights, "Number of circular test flights")->capture_default_str();
  sub.add_option("--out", opt->eval.out_dir, "Output directory (flights, survey, report)")->capture_default_str();
  opt->eval.addTo(sub);
  sub.callback([opt] {
    std::filesystem::create_directories(opt->eval.out_dir);
    const AnchorSurvey survey = sim::paperAnchors();
    writeAnchorSurvey(survey, (std::filesystem::path(opt->eval.out_dir) / "survey.txt").string());
    const std::vector<NamedFlight> train = {
        simulate("sim-zigzag", sim::TrajectoryShape::kZigzag, opt->train_duration_s, opt->seed, opt->seed,
                 opt->eval.out_dir)};
    std::vector<NamedFlight> test;
    for (int i = 0; i < opt->test_flights; ++i) {
      test.push_back(simulate(fmt::format("sim-circle{}", i + 1), sim::TrajectoryShape::kCircle, opt->test_duration_s,
                              opt->seed + 100 + static_cast<std::uint64_t>(i), opt->seed, opt->eval.out_dir));
    }
    runAndReport(train, test, survey, opt->eval);
  });
}

const bool kRegistered = registerCommand(
    {"demo", "The paper's experiment on simulated flights (zigzag → circle), end to end, with report", setup});

}  // namespace
}  // namespace uwb::app
