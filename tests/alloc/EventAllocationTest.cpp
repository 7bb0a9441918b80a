/** @file EventAllocationTest.cpp
 *  @brief The online estimator allocates no heap memory per event once it runs (filter/Estimator.h: "no allocation
 *         per event after the start-up"), without and with a trained bias model, alone and as the guarded pair (F24).
 *
 *  This executable counts heap allocations (malloc, calloc and realloc wrapped by the linker, operator new replaced),
 *  so it is its own test binary: every allocation of code linked into it passes through the counter while a test
 *  has it armed.
 */
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/eval/Localization.h"
#include "uwb/filter/BiasGuard.h"
#include "uwb/filter/CooperativeRange.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/SensorEvents.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
void count() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

// malloc, calloc and realloc of every object linked into this binary (the library's Eigen temporaries call malloc
// directly) are routed here by the linker (--wrap, tests/CMakeLists.txt); operator new goes through malloc.
extern "C" {
void* __real_malloc(std::size_t n);
void* __real_calloc(std::size_t n, std::size_t size);
void* __real_realloc(void* p, std::size_t n);
void* __wrap_malloc(std::size_t n) {
  count();
  return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t size) {
  count();
  return __real_calloc(n, size);
}
void* __wrap_realloc(void* p, std::size_t n) {
  count();
  return __real_realloc(p, n);
}
}

namespace {
void* allocateOrThrow(std::size_t n) {
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* allocateAlignedOrThrow(std::size_t n, std::align_val_t al) {
  count();
  const std::size_t a = static_cast<std::size_t>(al);
  if (void* p = std::aligned_alloc(a, (n + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
}  // namespace

// every form of the global operator new and delete, so that none of them pairs with the runtime's (or a sanitizer's)
void* operator new(std::size_t n) { return allocateOrThrow(n); }
void* operator new[](std::size_t n) { return allocateOrThrow(n); }
void* operator new(std::size_t n, std::align_val_t al) { return allocateAlignedOrThrow(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return allocateAlignedOrThrow(n, al); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return std::malloc(n == 0 ? 1 : n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return std::malloc(n == 0 ? 1 : n); }
void* operator new(std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  count();
  const std::size_t a = static_cast<std::size_t>(al);
  return std::aligned_alloc(a, (n + a - 1) / a * a);
}
void* operator new[](std::size_t n, std::align_val_t al, const std::nothrow_t& t) noexcept {
  return operator new(n, al, t);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

namespace uwb {
namespace {

/// Heap allocations made by the events after the first warm_up_s seconds of the log (the start-up: levelling,
/// multilateration, the replay of the start window), each event pushed as the batch path pushes it.
/// after_event(filter, event) runs after each event (e.g. a neighbour's range), counted alike.
template <class Filter, class AfterEvent>
long allocationsAfterWarmUp(Filter& filter, const SensorLog& log, double warm_up_s, std::size_t* n_counted,
                            const AfterEvent& after_event) {
  SensorEventCursor cursor(log);
  const double t_armed = cursor.firstStamp() + warm_up_s;
  long before = 0;
  *n_counted = 0;
  for (SensorEvent ev; cursor.next(ev);) {
    if (ev.t_s >= t_armed && !g_counting.load()) {
      before = g_allocations.load();
      g_counting.store(true);
    }
    switch (ev.kind) {
      case SensorEvent::Kind::kImu: filter.addImu(ev.t_s, log.imu[ev.index].imu); break;
      case SensorEvent::Kind::kTdoa: filter.addTdoa(log.tdoa[ev.index]); break;
      case SensorEvent::Kind::kTof: filter.addTof(log.tof[ev.index]); break;
    }
    after_event(filter, ev);
    if (filter.ready()) static_cast<void>(filter.estimate());
    if (g_counting.load()) ++*n_counted;
  }
  g_counting.store(false);
  return g_allocations.load() - before;
}

struct SimulatedFlight {
  sim::SimResult sim;
  SensorLog log;
  SensorLog log_with_tof;  ///< the same with a downward range at 25 Hz from the exact pose (the simulator has none)
};

/// A simulated flight with take-off, circle and landing (IMU, TDoA2 with the simulator's bias, ground truth).
const SimulatedFlight& flight() {
  static const SimulatedFlight f = [] {
    SimulatedFlight s;
    s.sim = sim::simulateFlight(sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kCircle, 40.0),
                                sim::SimParams{}, /*seed=*/5);
    s.log = sensorLogFromFlight(s.sim.flight);
    s.log_with_tof = s.log;
    double t_next = 0.0;
    for (const PoseSample& p : s.sim.pose_exact) {
      if (p.t_s < t_next) continue;
      const double cos_tilt = (p.w_q_b * Vec3::UnitZ()).z();
      s.log_with_tof.tof.push_back({p.t_s, p.w_p_b.z() / cos_tilt - EkfParams{}.tof_offset_m});  // (F21)
      t_next = p.t_s + 0.04;
    }
    return s;
  }();
  return f;
}

/// A small pair-tdoa-pos model (one SVGP per anchor pair, the default kernel) trained on the same flight.
const BiasModel& model() {
  static const BiasModel m = [] {
    BiasTrainParams p;
    p.preset = "pair-tdoa-pos";
    p.num_inducing = 10;
    p.svgp.epochs = 2;
    return trainBiasModel(buildBiasDataset({flight().sim.flight}, flight().sim.survey), p);
  }();
  return m;
}

/// Pushes the flight through `filter` and expects no allocation after the first 10 s, and a filter that worked.
template <class Filter>
void expectNoAllocationPerEvent(Filter& filter, const char* what, const SensorLog& log = flight().log) {
  std::size_t n = 0;
  const long allocations = allocationsAfterWarmUp(filter, log, 10.0, &n, [](Filter&, const SensorEvent&) {});
  EXPECT_GT(n, 20000u) << what;
  EXPECT_EQ(allocations, 0) << what << ", over " << n << " events";
  EXPECT_GT(filter.summary().n_tdoa_used, 5000u) << what;
}

TEST(EventAllocation, TheEstimatorAllocatesNothingPerEventOnceRunning) {
  // GIVEN the default filter on a simulated flight, and the same with the optional learners and models switched
  struct Variant {
    const char* name;
    EkfParams params;
  };
  std::vector<Variant> variants(5);
  variants[0].name = "defaults";
  variants[1].name = "antenna pattern learned in flight (F25)";
  variants[1].params.antenna_bias_degree = 3;
  variants[2].name = "without the range-bias states (F27)";
  variants[2].params.range_bias_sigma_m = 0.0;
  variants[3].name = "robust Cauchy update, bias floor off";
  variants[3].params.robust_loss = RobustLoss::kCauchy;
  variants[3].params.output_bias_sigma_m = 0.0;
  variants[4].name = "downward ToF fused (F21)";
  variants[4].params.fuse_tof = true;
  for (const Variant& v : variants) {
    Estimator est(v.params, anchorTableFromSurvey(flight().sim.survey));
    // WHEN every event after the first 10 s is pushed, THEN none of them touched the heap
    expectNoAllocationPerEvent(est, v.name, v.params.fuse_tof ? flight().log_with_tof : flight().log);
    if (v.params.fuse_tof) {
      EXPECT_GT(est.summary().n_tof_used, 500u);
    }
  }
}

TEST(EventAllocation, WithABiasModelTheFilterAllocatesNothingPerEvent) {
  // GIVEN a trained bias model (the GP predicted at every TDoA of the corrected filter), the corrected filter alone
  // and the default way a model runs: the corrected and the uncorrected filter side by side (F24)
  EkfParams alone;
  alone.bias_guard = false;
  applyBiasModelLevel(model(), &alone);
  EkfParams guarded;
  applyBiasModelLevel(model(), &guarded);
  Estimator corrected(alone, anchorTableFromSurvey(flight().sim.survey), model().predictor());
  GuardedEstimator pair(guarded, anchorTableFromSurvey(flight().sim.survey), model().predictor());
  // WHEN every event after the first 10 s is pushed, THEN none of them touched the heap
  expectNoAllocationPerEvent(corrected, "the corrected filter");
  expectNoAllocationPerEvent(pair, "the guarded pair");
}

TEST(EventAllocation, ARangeToANeighbourAllocatesNothing) {
  // GIVEN the filter of one agent of a swarm: a two-way range to a neighbour hovering at a known belief every 0.1 s,
  // fused by covariance intersection (G21), the path `uwbtdoa swarm` drives
  Estimator est(EkfParams{}, anchorTableFromSurvey(flight().sim.survey));
  Moments3 neighbour;
  neighbour.m = Vec3(0.5, -0.5, 1.0);
  neighbour.V = Mat3::Identity() * 0.01;
  const CooperativeRangeOptions options;
  const std::vector<PoseSample>& truth = flight().sim.pose_exact;
  double t_next = 0.0;
  std::size_t k = 0;
  const auto range = [&](Estimator& f, const SensorEvent& ev) {
    if (ev.t_s < t_next) return;
    while (k + 1 < truth.size() && truth[k + 1].t_s <= ev.t_s) ++k;
    static_cast<void>(f.addNeighbourRange(ev.t_s, neighbour, (truth[k].w_p_b - neighbour.m).norm(), options));
    t_next = ev.t_s + 0.1;
  };
  // WHEN every event and range after the first 10 s is pushed
  std::size_t n = 0;
  const long allocations = allocationsAfterWarmUp(est, flight().log, 10.0, &n, range);
  // THEN none of them touched the heap, and the ranges were fused
  EXPECT_EQ(allocations, 0) << "over " << n << " events";
  EXPECT_GT(est.summary().n_coop_used, 100u);
}

TEST(EventAllocation, AReacquisitionAllocatesNothing) {
  // GIVEN the flight with 3 s of garbage TDoA (uniform in ±10 m) from 20 s on: the gate rejects them, the estimate is
  // declared lost and found again by multilateration (F16)
  SensorLog log = flight().log;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> garbage(-10.0, 10.0);
  for (TdoaMeasurement& z : log.tdoa)
    if (z.t_s >= 20.0 && z.t_s < 23.0) z.tdoa_m = garbage(rng);
  Estimator est(EkfParams{}, anchorTableFromSurvey(flight().sim.survey));
  // WHEN every event after the first 10 s is pushed
  expectNoAllocationPerEvent(est, "garbage and re-acquisition", log);
  // THEN it re-acquired
  EXPECT_GE(est.summary().n_reacquisitions, 1u);
}

TEST(EventAllocation, TheCounterSeesAnAllocation) {
  // the counter itself: an armed allocation is counted (so that a zero above means something)
  const long before = g_allocations.load();
  g_counting.store(true);
  auto* v = new std::vector<double>(100);
  const VecX x = VecX::Ones(50);  // Eigen's heap storage goes through malloc, not operator new
  g_counting.store(false);
  delete v;
  EXPECT_EQ(x.size(), 50);
  EXPECT_GE(g_allocations.load() - before, 3);
}

}  // namespace
}  // namespace uwb
