/** @file bench_gp.cpp
 *  @brief SVGP speed: N = 50,000, D = 4, minibatch 1024, float64, RBF-ARD kernel; every row runs on ONE thread
 *         unless its name says otherwise (the predict rows' second argument is the thread count).
 *         BM_SvgpEpoch*: one epoch = the 49 minibatch steps and nothing else (the trainer's final full-data passes
 *         are switched off); BM_SvgpFinalPasses: those passes (optimal q(v) on the full data, P41, and the
 *         full-data ELBO, P15), which the trainer runs once after its last epoch; BM_SvgpTrainOneEpochDefaults:
 *         a one-epoch training with the trainer's defaults (all cores, both parts).
 *         Targets: 10,000 predictions at M = 170 in < 10 ms.
 *         GPyTorch 1.10 cannot be re-run from this repository: its figures in docs/results.md are a measurement
 *         reported elsewhere, quoted with its source and conditions, not a measurement of this benchmark.
 *
 *  Run: build/benchmarks/bench_gp --benchmark_repetitions=9 --benchmark_report_aggregates_only=true
 *  With UWB_NATIVE=ON (the default) the project is compiled with -march=native, so Eigen and the fused predictor use
 *  AVX2/FMA; UWB_NATIVE=OFF gives the portable SSE2 build (about 2× slower GEMMs).
 *  BM_EigenGemmCalibration measures the dense-GEMM rate of the core for comparison: the 10,000-point variance at
 *  M = 170 needs 0.29 GFlop (M² per point, already halved by the triangular Q_u, docs/math/gp.md P20).
 *  Measured figures: docs/results.md, "Speed".
 */
#include <benchmark/benchmark.h>

#include <random>

#include "uwb/gp/SvgpTrainer.h"

namespace {

using uwb::MatX;
using uwb::VecX;
using namespace uwb::gp;

struct Problem {
  MatX X;
  VecX y;
};

const Problem& problem() {
  static const Problem p = [] {
    Problem q;
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    std::normal_distribution<double> n(0.0, 0.1);
    const int N = 50000, D = 4;
    q.X.resize(N, D);
    q.y.resize(N);
    for (int i = 0; i < N; ++i) {
      for (int d = 0; d < D; ++d) q.X(i, d) = u(rng);
      q.y[i] = std::sin(q.X(i, 0)) * std::cos(q.X(i, 1)) + 0.3 * q.X(i, 2) - 0.2 * q.X(i, 3) * q.X(i, 3) + n(rng);
    }
    return q;
  }();
  return p;
}

Kernel rbfArd() {
  PartSpec s{PartType::kRbf, {0, 1, 2, 3}, 1.0, {1.0, 1.0, 1.0, 1.0}};
  return Kernel::sum({s});
}

Svgp makeModel(int M) {
  const Problem& p = problem();
  return initSvgp(rbfArd(), p.X, p.y, M, /*seed=*/1);
}

/// Training parameters of one epoch on one thread, without the final full-data passes.
SvgpTrainParams oneEpoch() {
  SvgpTrainParams params;
  params.epochs = 1;
  params.batch_size = 1024;
  params.num_threads = 1;
  params.final_full_data_q = false;
  params.final_full_data_elbo = false;
  return params;
}

/// One epoch (49 minibatch steps) of Adam on every parameter (hyperparameters, noise, mean, Z, m, L): GPyTorch's
/// setup. One thread. args: M, fast (1) or exact (0) ELBO.
void BM_SvgpEpochAdam(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  const ElboMode mode = state.range(1) ? ElboMode::kFast : ElboMode::kExact;
  Svgp gp = makeModel(M);
  SvgpTrainParams params = oneEpoch();
  params.natgrad_step = 0.0;  // Adam for m, L too
  params.mode = mode;
  for (auto _ : state) {
    trainSvgp(gp, problem().X, problem().y, params);
    benchmark::ClobberMemory();
  }
  state.SetLabel(mode == ElboMode::kFast ? "fast" : "exact");
}
BENCHMARK(BM_SvgpEpochAdam)->Args({30, 1})->Args({170, 1})->Args({30, 0})->Args({170, 0})->Unit(benchmark::kMillisecond)->UseRealTime();

/// One epoch (49 minibatch steps) of Adam (hyperparameters, Z) + natural-gradient steps on q(v), the default
/// training. One thread.
void BM_SvgpEpochNatgrad(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  Svgp gp = makeModel(M);
  SvgpTrainParams params = oneEpoch();
  params.natgrad_step = 0.2;
  for (auto _ : state) {
    trainSvgp(gp, problem().X, problem().y, params);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_SvgpEpochNatgrad)->Arg(30)->Arg(170)->Unit(benchmark::kMillisecond)->UseRealTime();

/// What the trainer adds once after its last epoch: q(v) set to its optimum on the full data (P41) and the
/// full-data ELBO (P15), two passes over all 50,000 points. One thread.
void BM_SvgpFinalPasses(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  Svgp gp = makeModel(M);
  for (auto _ : state) {
    setOptimalVariational(gp, problem().X, problem().y, 1);
    benchmark::DoNotOptimize(fullDataElbo(gp, problem().X, problem().y, 1).elbo);
  }
}
BENCHMARK(BM_SvgpFinalPasses)->Arg(30)->Arg(170)->Unit(benchmark::kMillisecond)->UseRealTime();

/// One call of `trainSvgp` with epochs = 1 and every other setting at the trainer's default: all cores
/// (num_threads = 0), natural gradients on q(v), and the two final full-data passes. What `uwbtdoa train` spends on
/// one epoch of a one-epoch run; the rows above split it into its parts on one thread.
void BM_SvgpTrainOneEpochDefaults(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  Svgp gp = makeModel(M);
  SvgpTrainParams params;
  params.epochs = 1;
  params.batch_size = 1024;
  for (auto _ : state) {
    trainSvgp(gp, problem().X, problem().y, params);
    benchmark::ClobberMemory();
  }
  state.SetLabel("all cores, final passes");
}
BENCHMARK(BM_SvgpTrainOneEpochDefaults)->Arg(30)->Arg(170)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Batch prediction of 10,000 points (mean, var_f, var_y) with a precomputed predictor; args: M, threads.
/// With threads > 1 the CPU column counts only the calling thread: read the wall-clock (Time) column.
void BM_SvgpPredictBatch(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const Svgp gp = makeModel(M);
  const SvgpPredictor pred = gp.predictor();
  const MatX Xt = problem().X.topRows(10000);
  for (auto _ : state) {
    SvgpPrediction p = pred.predict(Xt, threads);
    benchmark::DoNotOptimize(p.mean.data());
  }
  state.SetItemsProcessed(state.iterations() * Xt.rows());
}
BENCHMARK(BM_SvgpPredictBatch)
    ->Args({30, 1})
    ->Args({170, 1})
    ->Args({170, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// Batch prediction of the latent mean only for 10,000 points.
void BM_SvgpPredictMeanBatch(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  const Svgp gp = makeModel(M);
  const SvgpPredictor pred = gp.predictor();
  const MatX Xt = problem().X.topRows(10000);
  for (auto _ : state) {
    VecX mean = pred.predictMean(Xt);
    benchmark::DoNotOptimize(mean.data());
  }
}
BENCHMARK(BM_SvgpPredictMeanBatch)->Arg(30)->Arg(170)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Reference point for the machine's speed at the moment: one 170×170 · 170×1024 GEMM (59 MFlop).
void BM_EigenGemmCalibration(benchmark::State& state) {
  const MatX W = MatX::Random(170, 170), K = MatX::Random(170, 1024);
  MatX R(170, 1024);
  for (auto _ : state) {
    R.noalias() = W * K;
    benchmark::DoNotOptimize(R.data());
  }
  state.counters["GFlops"] = benchmark::Counter(2.0 * 170 * 170 * 1024 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EigenGemmCalibration)->Unit(benchmark::kMillisecond);

/// Single-point prediction (what the filter calls once per TDoA measurement).
void BM_SvgpPredictOne(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  const Svgp gp = makeModel(M);
  const SvgpPredictor pred = gp.predictor();
  const MatX& X = problem().X;
  Eigen::Index i = 0;
  for (auto _ : state) {
    double mean = 0, var = 0;
    pred.predictOne(X.row(i), mean, var);
    benchmark::DoNotOptimize(mean);
    benchmark::DoNotOptimize(var);
    i = (i + 1) % 10000;
  }
}
BENCHMARK(BM_SvgpPredictOne)->Arg(30)->Arg(170)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
