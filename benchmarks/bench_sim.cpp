/** @file bench_sim.cpp
 *  @brief Flight simulator throughput: a whole flight (the issue asks for 10 min in a few seconds) and its parts.
 */
#include <benchmark/benchmark.h>

#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Kinematics.h"

namespace {

using namespace uwb::sim;

/// Whole flight of state.range(0) seconds (default params: IMU 1 kHz, pose 300 Hz, TDoA 400 Hz).
void BM_SimulateFlight(benchmark::State& state) {
  const Scenario sc = makeScenario(paperAnchors(), TrajectoryShape::kZigzag, static_cast<double>(state.range(0)));
  const SimParams params;
  std::size_t n_tdoa = 0;
  for (auto _ : state) {
    const SimResult r = simulateFlight(sc, params, 1);
    n_tdoa = r.flight.tdoa.size();
    benchmark::DoNotOptimize(r.flight.tdoa.data());
  }
  state.counters["tdoa"] = static_cast<double>(n_tdoa);
  state.counters["flight_s_per_s"] =
      benchmark::Counter(static_cast<double>(state.range(0)) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateFlight)->Arg(60)->Arg(600)->Unit(benchmark::kMillisecond);

/// One kinematic state (3 trajectory evaluations and 3 attitudes: the inner loop of every stream).
void BM_KinematicState(benchmark::State& state) {
  TrajectoryParams p;
  p.shape = TrajectoryShape::kCircleSine;
  const Trajectory traj(p);
  double t = 10.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(kinematicState(traj, t));
    t += 1e-3;
    if (t > 40.0) t = 10.0;
  }
}
BENCHMARK(BM_KinematicState);

/// One TDoA error sample (two anchor patterns, two multipath fields, noise draws).
void BM_BiasSample(benchmark::State& state) {
  std::mt19937_64 rng(1);
  const SimulatedBias model(BiasParams{}, paperAnchors(), rng);
  const uwb::Quat q(Eigen::AngleAxisd(0.3, uwb::Vec3::UnitZ()));
  uwb::Vec3 p(0.2, 0.1, 1.5);
  for (auto _ : state) {
    benchmark::DoNotOptimize(model.sample(1.0, 2, 3, p, q, 1.5, rng));
    p.x() += 1e-4;
  }
}
BENCHMARK(BM_BiasSample);

}  // namespace

BENCHMARK_MAIN();
