/** @file bench_gp_train.cpp
 *  @brief SVGP training at scale: k-means++ initialization and one natural-gradient epoch on N synthetic samples
 *         with the paper's `tdoa` kernel (eq. 9, 6 input columns), M = 30, B = 1024, on one and on two threads.
 *
 *  Peak memory is the point of the large case: run it alone under /usr/bin/time -v and read "Maximum resident set
 *  size". The inputs X (N × 6 float64) and y take 56 bytes per sample (560 MB at N = 10⁷); everything else the
 *  trainer needs is O(B·M + M²) per thread plus O(N) indices for the shuffle (docs/math/gp.md P21, P40–P42).
 *
 *    build/benchmarks/bench_gp_train --benchmark_filter='TrainEpoch/10000000/2'
 *    build/benchmarks/bench_gp_train --benchmark_filter='TrainEpoch/200000'     # speed, one vs two threads
 *
 *  Measured (/usr/bin/time -v, N = 10⁷, two threads): maximum resident set 637 MB, of which X and y are 560 MB
 *  and the shuffle's index vector 80 MB (GPyTorch 1.10 on the same problem: about 0.7 GB). Keeping a transformed
 *  copy of X for k-means++ and a second copy inside it would add 2 × 480 MB (1.57 GB measured that way).
 */
#include <benchmark/benchmark.h>

#include <random>

#include "uwb/gp/SvgpTrainer.h"

namespace {

using uwb::MatX;
using uwb::VecX;
using namespace uwb::gp;

/// Anchor vectors in the body frame, as the `tdoa` features: b_p_a, b_p_b in a 6 m room, bias from their angles.
void makeData(Eigen::Index N, MatX& X, VecX& y) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::normal_distribution<double> n(0.0, 0.1);
  X.resize(N, 6);
  y.resize(N);
  for (Eigen::Index i = 0; i < N; ++i) {
    for (int d = 0; d < 6; ++d) X(i, d) = u(rng);
    X(i, 2) += 4.0;  // keep the vectors away from zero (k_L needs a direction)
    X(i, 5) += 4.0;
    y[i] = 0.1 * std::atan2(X(i, 1), X(i, 0)) - 0.05 * std::atan2(X(i, 4), X(i, 3)) + n(rng);
  }
}

void TrainEpoch(benchmark::State& state) {
  const Eigen::Index N = state.range(0);
  MatX X;
  VecX y;
  makeData(N, X, y);
  SvgpTrainParams params;
  params.epochs = 1;
  params.batch_size = 1024;
  params.num_threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    Svgp gp = initSvgp(Kernel::preset("tdoa"), X, y, 30, 1);
    const SvgpTrainSummary s = trainSvgp(gp, X, y, params);
    benchmark::DoNotOptimize(s.final_elbo);
  }
  state.counters["samples"] = static_cast<double>(N);
}
BENCHMARK(TrainEpoch)
    ->Args({200000, 1})
    ->Args({200000, 2})
    ->Args({10000000, 2})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
