/** @file bench_filter.cpp
 *  @brief Cost of one IMU prediction, one covariance propagation, one TDoA update (graph node), and a whole flight
 *         (real-time factor).
 *         Run: build/benchmarks/bench_filter --benchmark_repetitions=7 --benchmark_report_aggregates_only=true
 *         The flight benchmark uses 0425-traj2 when the data is present, else a synthetic 40 s flight with 1 kHz IMU
 *         and 400 Hz TDoA. Real-time factors (flight duration / run time): `rtf` and `rtf_cpu` use the CPU time of the
 *         benchmark thread (Google Benchmark divides kIsRate counters by CPU time), `rtf_wall` the wall-clock time of
 *         the timed loop. On a shared machine quote rtf_cpu; rtf_wall also counts time spent waiting for a core.
 *         Measured figures: docs/results.md, "Speed".
 */
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <random>

#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/eval/Localization.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/FlightMode.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

AnchorTable benchAnchors() {
  AnchorTable t;
  const Vec3 c[8] = {{-3, -4, 0.2}, {-3, 4, 3}, {3.5, 4, 0.2}, {4, -4, 3}, {-3, -4.2, 3}, {4, -3.8, 0.2}, {4, 4, 3},
                     {-3, 3.5, 0.2}};
  for (int i = 0; i < 8; ++i) t.set(i, c[i]);
  return t;
}

/// Synthetic circle flight (r = 1.5 m, ω = 0.6 rad/s, z = 1.5 m): 1 kHz IMU, 400 Hz TDoA on neighbour pairs.
SensorLog syntheticFlight(const AnchorTable& anchors, double duration_s) {
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  SensorLog log;
  const double w = 0.6, r = 1.5;
  for (double t = 0.0; t <= duration_s; t += 0.001) {
    TimedImu s;
    s.t_s = t;
    const Vec3 a(-r * w * w * std::cos(w * t), -r * w * w * std::sin(w * t), 0.0);
    s.imu.b_acc_mps2 = a + Vec3(0, 0, kGravity_mps2) + 0.5 * Vec3(n(rng), n(rng), n(rng));
    s.imu.b_gyro_radps = 0.08 * Vec3(n(rng), n(rng), n(rng));
    log.imu.push_back(s);
  }
  int k = 0;
  for (double t = 0.0; t <= duration_s; t += 0.0025, ++k) {
    const int ia = k % 8, ib = (k + 1) % 8;
    const Vec3 p(r * std::cos(w * t), r * std::sin(w * t), 1.5);
    const Vec3 tag = tagPosition(p, Quat::Identity(), kUtilTagOffset_b);
    log.tdoa.push_back({t, ia, ib, range(tag, anchors.find(ib)->m) - range(tag, anchors.find(ia)->m) + 0.1 * n(rng)});
  }
  return log;
}

/// CPU time of the calling thread [s].
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// Runs the localizer over `log` once per benchmark iteration and reports rtf (CPU, Google Benchmark rate),
/// rtf_cpu (CPU, measured here) and rtf_wall (wall clock, measured here).
void runFlightBenchmark(benchmark::State& state, const TdoaLocalizer& localizer, const SensorLog& log,
                        double duration_s) {
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = threadCpuSeconds();
  for (auto _ : state) benchmark::DoNotOptimize(localizer.run(log));
  const double cpu_s = threadCpuSeconds() - cpu0;
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const double flown_s = duration_s * static_cast<double>(state.iterations());
  state.counters["rtf"] = benchmark::Counter(flown_s, benchmark::Counter::kIsRate);
  state.counters["rtf_cpu"] = flown_s / cpu_s;
  state.counters["rtf_wall"] = flown_s / wall_s;
}

void BM_ImuPrediction(benchmark::State& state) {
  Ekf ekf(EkfParams{});
  NavState x;
  x.w_p_b = Vec3(0, 0, 1.5);
  ekf.initialize(x, initialCovariance(EkfParams{}));
  ImuReading imu;
  imu.b_gyro_radps = Vec3(0.01, -0.02, 0.03);
  for (auto _ : state) {
    ekf.predict(imu, 0.0025);  // nominal integration + Φ accumulation (F2–F7)
    benchmark::DoNotOptimize(ekf.state());
  }
}
BENCHMARK(BM_ImuPrediction);

void BM_CovariancePropagation(benchmark::State& state) {
  Ekf ekf(EkfParams{});
  ekf.initialize(NavState{}, initialCovariance(EkfParams{}));
  ImuReading imu;
  for (auto _ : state) {
    ekf.predict(imu, 0.0025);
    ekf.propagateCovariance();  // P ← Φ P Φᵀ + Q (F7)
    benchmark::DoNotOptimize(ekf.covariance());
  }
}
BENCHMARK(BM_CovariancePropagation);

void BM_TdoaUpdate(benchmark::State& state) {
  // arg 0: defaults (with the range-bias states, F27: the equality node on [δx, δβ]); 1: without them
  const AnchorTable anchors = benchAnchors();
  EkfParams params;
  if (state.range(0) == 1) params.range_bias_sigma_m = 0.0;
  Ekf ekf(params);
  NavState x;
  x.w_p_b = Vec3(0.3, -0.2, 1.5);
  ekf.initialize(x, initialCovariance(params));
  TdoaUpdateOptions opt;
  opt.gate_sigma = 0.0;
  const Vec3 tag = tagPosition(x.w_p_b, x.w_q_b, kUtilTagOffset_b);
  const double z = range(tag, anchors.find(1)->m) - range(tag, anchors.find(0)->m);
  const ErrMat P0 = ekf.covariance();
  std::size_t i = 0;
  for (auto _ : state) {
    if ((++i & 1023u) == 0) ekf.initialize(x, P0);  // keep P from collapsing
    benchmark::DoNotOptimize(updateTdoa(ekf, anchors, {0.0, 0, 1, z + 0.05}, opt));  // graph TDoA node + equality
  }
}
BENCHMARK(BM_TdoaUpdate)->Arg(0)->Arg(1);

/// One online Estimator event at steady state: the estimator has run 5 s of the synthetic flight; the timed loop feeds
/// the next events of the same kind (IMU or TDoA) from the following 30 s, wrapping the log's time forward.
void runEstimatorEvents(benchmark::State& state, SensorEvent::Kind kind) {
  const AnchorTable anchors = benchAnchors();
  const SensorLog log = syntheticFlight(anchors, 40.0);
  EkfParams p;
  p.ground_phase = GroundPhase::kNone;
  Estimator est(p, anchors);
  SensorEventCursor cursor(log);
  std::vector<SensorEvent> later;
  for (SensorEvent ev; cursor.next(ev);) {
    if (ev.t_s < 5.0) {
      if (ev.kind == SensorEvent::Kind::kImu) est.addImu(ev.t_s, log.imu[ev.index].imu);
      else if (ev.kind == SensorEvent::Kind::kTdoa) est.addTdoa(log.tdoa[ev.index]);
    } else {
      later.push_back(ev);
    }
  }
  // manual timing around the one timed event; the clock reads are part of the figure (BM_EstimatorEventClock)
  std::size_t i = 0;
  for (auto _ : state) {
    for (;;) {
      const SensorEvent& ev = later[i];
      i = (i + 1) % later.size();
      if (i == 0) state.SkipWithError("log exhausted; lower the iteration count");
      const bool timed = ev.kind == kind;
      const auto t0 = std::chrono::steady_clock::now();
      if (ev.kind == SensorEvent::Kind::kImu) est.addImu(ev.t_s, log.imu[ev.index].imu);
      else est.addTdoa(log.tdoa[ev.index]);
      if (timed) {
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        break;
      }
    }
    benchmark::DoNotOptimize(est.state());
  }
}
/// The manual timing of the two rows below around an empty region: the clock reads' own cost, to be subtracted from
/// them (a few tens of ns with the TSC as clock source; several hundred under a virtual machine's kvm-clock).
void BM_EstimatorEventClock(benchmark::State& state) {
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::ClobberMemory();
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
}
BENCHMARK(BM_EstimatorEventClock)->Iterations(30000)->UseManualTime()->Unit(benchmark::kNanosecond);
void BM_EstimatorImuEvent(benchmark::State& state) { runEstimatorEvents(state, SensorEvent::Kind::kImu); }
BENCHMARK(BM_EstimatorImuEvent)->Iterations(30000)->UseManualTime()->Unit(benchmark::kNanosecond);
void BM_EstimatorTdoaEvent(benchmark::State& state) { runEstimatorEvents(state, SensorEvent::Kind::kTdoa); }
BENCHMARK(BM_EstimatorTdoaEvent)->Iterations(12000)->UseManualTime()->Unit(benchmark::kNanosecond);

/// The flight-mode supervisor's share of an event (filter.md F29): one IMU step with its decision, and one TDoA
/// folded into the height window, as the estimator calls them; compare with BM_EstimatorImuEvent / TdoaEvent.
void BM_FlightModeImuStep(benchmark::State& state) {
  FlightModeSupervisor s;
  s.reset(FlightMode::kAirborne);
  double t = 0.0;
  const ImuModeEvidence e{false, false, false, 0.003};
  for (auto _ : state) {
    t += 0.001;
    s.addImu(t, 0.001, e, true);
    benchmark::DoNotOptimize(s.decide(t));
  }
}
BENCHMARK(BM_FlightModeImuStep)->Unit(benchmark::kNanosecond);
/// The same with a downward range (F29f) at 25 Hz: one reading into its window every 40 IMU steps.
void BM_FlightModeImuStepWithTof(benchmark::State& state) {
  FlightModeSupervisor s;
  s.reset(FlightMode::kAirborne);
  double t = 0.0;
  int k = 0;
  const ImuModeEvidence e{false, false, false, 0.003};
  for (auto _ : state) {
    t += 0.001;
    if (++k % 40 == 0) s.addTof(t, 1.2 + 0.01 * (k % 3));
    s.addImu(t, 0.001, e, true);
    benchmark::DoNotOptimize(s.decide(t));
  }
}
BENCHMARK(BM_FlightModeImuStepWithTof)->Unit(benchmark::kNanosecond);
void BM_FlightModeTdoa(benchmark::State& state) {
  FlightModeSupervisor s;
  s.reset(FlightMode::kAirborne);
  double t = 0.0, r = 0.01;
  for (auto _ : state) {
    t += 0.0025;
    r = -r;
    s.addTdoa(t, r, r, 0.6, 1.5);
    benchmark::DoNotOptimize(s.tdoaLogOdds());
  }
}
BENCHMARK(BM_FlightModeTdoa)->Unit(benchmark::kNanosecond);

void BM_WholeFlightSynthetic(benchmark::State& state) {
  const AnchorTable anchors = benchAnchors();
  const double duration = 40.0;
  const SensorLog log = syntheticFlight(anchors, duration);
  EkfParams p;
  p.ground_phase = GroundPhase::kNone;
  const TdoaLocalizer localizer(p, anchors);
  runFlightBenchmark(state, localizer, log, duration);
}
BENCHMARK(BM_WholeFlightSynthetic)->Unit(benchmark::kMillisecond);

void BM_WholeFlightReal0425Traj2(benchmark::State& state) {
  const char* env = std::getenv("UWBTDOA_DATA");
  const std::filesystem::path data = (env && *env) ? std::filesystem::path(env) : std::filesystem::path(UWB_DEFAULT_DATA_DIR);
  const std::filesystem::path flight = data / "real/util-pilot/0425/0425-traj2.csv";
  if (!std::filesystem::exists(flight)) {
    state.SkipWithError("real data absent");
    return;
  }
  const AnchorSurvey survey = readAnchorSurvey((data / "real/util-pilot/survey/anchor_0425_survey.txt").string());
  const Flight f = readFlightCsv(flight.string());
  const SensorLog log = sensorLogFromFlight(f);
  // arg 0: defaults; 1: the tag antenna pattern learned in flight (F25, degree 3); 2: the bias guard (F24) with a
  // zero-mean bias model, i.e. two filters side by side; 3: without the range-bias states (F27); 4: without the
  // in-motion heading alignment (F28); 5: a trained model, `train`'s default (pair-tdoa-pos, M = 30) of 0425-traj1,
  // as `localize --bias-model` runs it (guarded, GP mean and variance at every TDoA of the corrected filter)
  EkfParams p;
  BiasPredictor bias;
  if (state.range(0) == 5) {
    const std::filesystem::path other = data / "real/util-pilot/0425/0425-traj1.csv";
    BiasTrainParams tp;
    tp.preset = kDefaultTrainPreset;
    BiasDatasetParams dp;
    dp.inputs = BiasInputSource::kFilterEstimate;
    const BiasModel model = trainBiasModel(buildBiasDataset({readFlightCsv(other.string())}, survey, dp), tp);
    applyBiasModelLevel(model, &p);
    bias = model.predictor();
  }
  if (state.range(0) == 1) p.antenna_bias_degree = 3;
  if (state.range(0) == 3) {
    p.range_bias_sigma_m = 0.0;
    p.tdoa_sigma_m = 0.35;
  }
  if (state.range(0) == 4) p.heading_alignment = false;
  if (state.range(0) == 2) {
    p.bias_guard = true;
    bias = [](const TdoaFeature&) { return BiasPrediction{}; };
  }
  const TdoaLocalizer localizer(p, anchorTableFromSurvey(survey), bias);
  const double duration = f.timeSpan().second - f.timeSpan().first;
  runFlightBenchmark(state, localizer, log, duration);
}
BENCHMARK(BM_WholeFlightReal0425Traj2)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4)->Arg(5)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace uwb

BENCHMARK_MAIN();
