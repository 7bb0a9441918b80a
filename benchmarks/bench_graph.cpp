/** @file bench_graph.cpp
 *  @brief Cost of one TDoA correction (paper Fig. 3) on a 15-dim error state: linearization (eq. 4), TDoA node
 *         forward pass, message on the state and the rank-one equality node (docs/math/message-passing.md G11–G18).
 *
 *  Run: bench_graph --benchmark_repetitions=20 --benchmark_report_aggregates_only=true  (report the median).
 */
#include <benchmark/benchmark.h>

#include <random>

#include "uwb/graph/Nodes.h"
#include "uwb/graph/TdoaCorrection.h"
#include "uwb/model/TdoaModel.h"

namespace {

using namespace uwb;
constexpr int kN = 15;
using VecN = Eigen::Matrix<double, kN, 1>;
using MatN = Eigen::Matrix<double, kN, kN>;

struct Scene {
  Vec3 w_p_b{0.3, -0.4, 1.2};
  Quat w_q_b{Eigen::AngleAxisd(0.4, Vec3(0.1, 0.2, 1.0).normalized())};
  Vec3 b_t_tag = kUtilTagOffset_b;
  Moments3 anchor_a{Vec3(4.0, -3.5, 0.2), Mat3::Identity() * 1e-4};
  Moments3 anchor_b{Vec3(-4.1, 3.6, 2.7), Mat3::Identity() * 1e-4};
  double z_m = 0.7;
  double var_m2 = 0.02;
  MatN P;
  Scene() {
    std::mt19937 rng(1);
    std::normal_distribution<double> n(0.0, 1.0);
    MatN A;
    for (int i = 0; i < kN; ++i)
      for (int j = 0; j < kN; ++j) A(i, j) = n(rng);
    P = A * A.transpose() / kN * 0.01 + MatN::Identity() * 1e-3;
  }
};

/// What one iteration of an in-place update leaves, its outcome and the covariance, kept from being optimized away.
template <class Outcome>
void keepResult(const Outcome& outcome, MatN& P) {
  benchmark::DoNotOptimize(outcome);
  benchmark::DoNotOptimize(P.data());
  benchmark::ClobberMemory();
}

// One full TDoA correction as the filter would call it (everything except the prior copy is measured work).
void BM_TdoaCorrection15(benchmark::State& state) {
  const Scene s;
  VecN dx;
  MatN P;
  for (auto _ : state) {
    dx.setZero();
    P = s.P;
    const Vec3 p_tag = tagPosition(s.w_p_b, s.w_q_b, s.b_t_tag);
    const auto lin = linearizeTdoa(p_tag, s.anchor_b.m, s.anchor_a.m);
    const TdoaNodeMessages msg = tdoaNodeForward(*lin, s.anchor_b, s.anchor_a, s.z_m, s.var_m2);
    Eigen::Matrix<double, 3, kN> C = Eigen::Matrix<double, 3, kN>::Zero();
    C.block<3, 3>(0, 0).setIdentity();
    C.block<3, 3>(0, 6) = tagPositionJacobianAttitude(s.w_q_b, s.b_t_tag);
    const ScalarLinearMessage<kN> on_state = tdoaMessageOnState<kN>(msg, C, p_tag);
    const auto st = equalityRankOneInPlace<kN>(dx, P, on_state);
    keepResult(st, P);
  }
}
BENCHMARK(BM_TdoaCorrection15);

// Only the equality node (Kalman-gain form, Joseph covariance) on a 15-dim state.
void BM_EqualityRankOne15(benchmark::State& state) {
  const Scene s;
  ScalarLinearMessage<kN> msg;
  msg.a = Eigen::Matrix<double, 1, kN>::Zero();
  msg.a.head<3>() << 0.6, -0.64, 0.48;
  msg.y = 0.1;
  msg.var = 0.02;
  VecN dx;
  MatN P;
  for (auto _ : state) {
    dx.setZero();
    P = s.P;
    const auto st = equalityRankOneInPlace<kN>(dx, P, msg);
    keepResult(st, P);
  }
}
BENCHMARK(BM_EqualityRankOne15);

// The generic dynamic-size message-passing route (information form, n×n LU), for comparison only.
void BM_TdoaCorrectionGenericDynamic15(benchmark::State& state) {
  const Scene s;
  const Vec3 p_tag = tagPosition(s.w_p_b, s.w_q_b, s.b_t_tag);
  const auto lin = linearizeTdoa(p_tag, s.anchor_b.m, s.anchor_a.m);
  const TdoaNodeMessages msg = tdoaNodeForward(*lin, s.anchor_b, s.anchor_a, s.z_m, s.var_m2);
  MatX C = MatX::Zero(3, kN);
  C.block<3, 3>(0, 0).setIdentity();
  C.block<3, 3>(0, 6) = tagPositionJacobianAttitude(s.w_q_b, s.b_t_tag);
  const Moments prior{VecX::Zero(kN), MatX(s.P)};
  for (auto _ : state) {
    auto post = correctTdoaByMessages(prior, C, p_tag, msg);
    benchmark::DoNotOptimize(post);
  }
}
BENCHMARK(BM_TdoaCorrectionGenericDynamic15);

}  // namespace

BENCHMARK_MAIN();
