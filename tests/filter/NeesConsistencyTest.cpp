/** @file NeesConsistencyTest.cpp
 *  @brief Monte-Carlo consistency (STYLE §10): the position NEES of the filter on simulated hover flights with white
 *         TDoA noise and matched filter noise stays within χ² bounds. Runs in ≈0.2 s: in the default suite.
 *
 *  The simulated flights here are generated in the test (the filter's tests link only the filter); the measurement
 *  noise is white, so σ_tdoa is set to its true value (no correlation inflation, F12), and gate/robust loss are off.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

TEST(NeesConsistency, PositionNeesWithinChiSquareBounds) {
  // GIVEN N Monte-Carlo hover flights with white TDoA noise (σ = 0.1 m) and a matched filter
  AnchorTable anchors;
  const Vec3 c[8] = {{-3, -4, 0.2}, {-3, 4, 3}, {3.5, 4, 0.2}, {4, -4, 3}, {-3, -4.2, 3}, {4, -3.8, 0.2}, {4, 4, 3},
                     {-3, 3.5, 0.2}};
  for (int i = 0; i < 8; ++i) anchors.set(i, c[i]);
  const int kRuns = 12;
  const double sigma = 0.1, duration = 8.0, acc_std = 0.5, gyro_std = 0.02;
  EkfParams p;
  p.ground_phase = GroundPhase::kNone;
  p.tdoa_sigma_m = sigma;
  p.range_bias_sigma_m = 0.0;  // white TDoA noise: no range biases to carry (F27)
  p.robust_loss = RobustLoss::kNone;
  p.gate_sigma = 100.0;
  p.cov_period_s = 0.0;
  p.acc_noise_mps2_sqrthz = acc_std * std::sqrt(0.001);   // white per-sample std → spectral density
  p.lateral_acc_noise_mps2_sqrthz = 0.05;
  p.gyro_noise_radps_sqrthz = gyro_std * std::sqrt(0.001);
  p.output_bias_sigma_m = 0.0;  // white TDoA noise: no correlated bias to report (F23)
  double nees_sum = 0.0;
  std::size_t n = 0;
  for (int run = 0; run < kRuns; ++run) {
    SCOPED_TRACE("seed " + std::to_string(run));
    std::mt19937 rng(1000 + run);
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Vec3 p_true(u(rng), u(rng), 1.5 + 0.3 * u(rng));
    SensorLog log;
    for (double t = 0.0; t <= duration; t += 0.001) {
      TimedImu s;
      s.t_s = t;
      s.imu.b_acc_mps2 = Vec3(0, 0, kGravity_mps2) + acc_std * Vec3(g(rng), g(rng), g(rng));
      s.imu.b_gyro_radps = gyro_std * Vec3(g(rng), g(rng), g(rng));
      log.imu.push_back(s);
    }
    int k = 0;
    for (double t = 0.0; t <= duration; t += 0.0025, ++k) {
      const int a = k % 8, b = (k + 1) % 8;
      const Vec3 tag = tagPosition(p_true, Quat::Identity(), kUtilTagOffset_b);
      log.tdoa.push_back({t, a, b, range(tag, anchors.find(b)->m) - range(tag, anchors.find(a)->m) + sigma * g(rng)});
    }
    // WHEN localizing
    const LocalizerResult r = TdoaLocalizer(p, anchors).run(std::move(log), 0.5);
    // THEN accumulate the position NEES after convergence (one sample per 0.5 s: nearly independent)
    for (const LocalizerEstimate& e : r.estimates) {
      if (e.t_s < 3.0) continue;
      const Vec3 err = e.x.w_p_b - p_true;
      const Vec3 s2 = e.sigma_p_m.cwiseAbs2();
      nees_sum += (err.array().square() / s2.array()).sum();  // diagonal NEES (3 dof)
      ++n;
    }
  }
  ASSERT_GT(n, 50u);
  // mean NEES ≈ 3 for a consistent filter; χ²(3n)/n bounds at 99.9 % are roughly 3 ± 3.3·√(6/n); allow
  // correlated samples and the diagonal approximation with a factor-2 band.
  const double mean_nees = nees_sum / static_cast<double>(n);
  EXPECT_GT(mean_nees, 3.0 / 2.5) << "filter too conservative";
  EXPECT_LT(mean_nees, 3.0 * 2.5) << "filter overconfident";
  RecordProperty("mean_position_nees", std::to_string(mean_nees));
  std::printf("mean position NEES over %zu samples: %.2f (ideal 3)\n", n, mean_nees);
}

}  // namespace
}  // namespace uwb
