/** @file bench_gp.cpp
 *  @brief SVGP speed against the GPyTorch 1.10 reference measured on this machine (issue 4):
 *         N = 50,000, D = 4, minibatch 1024, one thread, float64, RBF-ARD kernel.
 *         GPyTorch (Adam): 0.51 s/epoch at M = 30, 1.51 s/epoch at M = 170.
 *         Targets: ≥ 10× faster at M = 30, ≥ 3× at M = 170; 10,000 predictions at M = 170 in < 10 ms.
 *
 *  Run: build-gp/benchmarks/bench_gp --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
 *  Eigen vectorizes with SSE2 only in the default build; configure with -DCMAKE_CXX_FLAGS=-march=native (whole
 *  project, so every translation unit agrees) for AVX2/FMA, about 2× faster GEMMs.
 *  Measured 2026-11-21 on the shared 2-core EPYC (load ≈ 8–10, CPU-time medians of 5):
 *    before (0552d0b):
 *      default:        epoch M=30 46 ms, M=170 1.00 s; predict 10k (mean+var) M=170 70 ms, mean only 14 ms;
 *                      one point M=30/170 1.2/10.5 µs
 *      -march=native:  epoch M=30 25 ms, M=170 0.54 s; predict 10k (mean+var) M=170 35 ms, mean only 5.2 ms;
 *                      one point 1.0/7.7 µs
 *    after (predictor with α and Q, P20; T1 reuse and GEMM kernel gradients in training, P17/P8):
 *      default:        epoch (Adam) M=30 46 ms, M=170 0.84 s; natgrad M=30 44 ms, M=170 0.86 s;
 *                      predict 10k (mean+var) M=30 3.9 ms, M=170 35 ms, mean only 14 ms; one point 0.54/6.6 µs
 *      -march=native:  epoch (Adam) M=30 22 ms, M=170 0.38–0.43 s; natgrad M=30 24 ms, M=170 0.42 s;
 *                      predict 10k (mean+var) M=30 1.7 ms, M=170 17 ms, mean only 4.9 ms; one point 0.32/3.6 µs
 *    session 2 (machine nearly idle, native): predict 10k M=170 one thread 17.6–18.7 ms, two threads 10.8–11.4 ms
 *      wall (the two vCPUs share resources: 1.6×); mean only 5.0 ms; one point 0.36/4.4 µs.
 *    GEMM calibration: 15 GFlop/s (default), 27–30 GFlop/s (native). The 10k/M=170 variance needs 0.29 GFlop
 *    (M² per point, already halved by the triangular Q_u): ≥ 10 ms at Eigen's GEMM rate on one float64 core.
 *    session 3 (fused predictor: Kernel::crossInto with a polynomial exp, P32; register-blocked kᵀQ_u k over 8-point
 *      tiles, P33; threads pull 128-row blocks from a counter), native, medians of 7, wall clock:
 *      before (c2f16be, uptime load 4.3–4.6, the other developer compiling): M=170 one thread 29.3 ms (CPU 19.3),
 *        two threads 36.7 ms; mean only 7.9 ms (CPU 5.3); M=30 2.0 ms; one point 0.60/6.8 µs (CPU 0.40/4.5)
 *      after (uptime load 1.8–2.2: bench_filter at 100 % on the other vCPU; GEMM calibration 25.4 GFlop/s):
 *        M=170 one thread 10.9–11.0 ms (CPU the same), two threads 10.4–10.7 ms (second thread shares a vCPU
 *        with bench_filter); mean only 3.4 ms; M=30 0.87–0.93 ms; one point 0.37–0.40/4.3–4.6 µs (path unchanged)
 *      later rounds (load 1.2–2.5, another benchmark or compiler on the other vCPU): one thread 11.0–13.2 ms
 *        (CPU 9.9–11.9), two threads 9.8–11.1 ms, mean only 3.4–3.7 ms; GEMM calibration 20.8–24.8 GFlop/s.
 *        No quiet window for a clean two-thread figure.
 *    Where the 11 ms go (one thread): kᵀQ_u k ≈ 7.4 ms = 39 GFlop/s, 80–85 % of the 46–50 GFlop/s this vCPU
 *    reaches in a register-only FMA loop; the kernel block ≈ 2.4–3.0 ms (1.7 M values, exp by a degree-11
 *    polynomial, ≈ 1.4 ns each); the mean ≈ 0.3 ms. At 100 % of FMA peak the variance alone would take ≈ 6 ms.
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

/// One epoch (49 minibatches) of Adam on every parameter (hyperparameters, noise, mean, Z, m, L): GPyTorch's setup.
void BM_SvgpEpochAdam(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  const ElboMode mode = state.range(1) ? ElboMode::kFast : ElboMode::kExact;
  Svgp gp = makeModel(M);
  SvgpTrainParams params;
  params.epochs = 1;
  params.batch_size = 1024;
  params.natgrad_step = 0.0;  // Adam for m, L too
  params.mode = mode;
  for (auto _ : state) {
    trainSvgp(gp, problem().X, problem().y, params);
    benchmark::ClobberMemory();
  }
  state.SetLabel(mode == ElboMode::kFast ? "fast" : "exact");
}
BENCHMARK(BM_SvgpEpochAdam)->Args({30, 1})->Args({170, 1})->Args({30, 0})->Args({170, 0})->Unit(benchmark::kMillisecond)->UseRealTime();

/// One epoch of Adam (hyperparameters, Z) + natural-gradient steps on q(v), the default training.
void BM_SvgpEpochNatgrad(benchmark::State& state) {
  const int M = static_cast<int>(state.range(0));
  Svgp gp = makeModel(M);
  SvgpTrainParams params;
  params.epochs = 1;
  params.batch_size = 1024;
  params.natgrad_step = 0.2;
  for (auto _ : state) {
    trainSvgp(gp, problem().X, problem().y, params);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_SvgpEpochNatgrad)->Arg(30)->Arg(170)->Unit(benchmark::kMillisecond)->UseRealTime();

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
