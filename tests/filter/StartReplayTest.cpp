/** @file StartReplayTest.cpp
 *  @brief The start-up window run again from the fix (docs/math/filter.md F16g): the replay is the filter run from
 *         the restarted state, a record that overflowed or was stopped is not replayed, and a start in the air takes
 *         the replay.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "FilterTestUtil.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/StartReplay.h"
#include "uwb/filter/TdoaLocalizer.h"

namespace uwb {
namespace {

NavState movingState() {
  NavState x;
  x.w_p_b = Vec3(0.5, -0.3, 1.2);
  x.w_v_b = Vec3(0.4, -0.2, 0.05);
  x.w_q_b = expQuat(Vec3(0.03, -0.02, 0.4));
  return x;
}

/// Predictions at 1 kHz and a TDoA every 2.5 ms over 0.3 s, with noise; `apply` gets each in order.
template <class Apply>
void windowEvents(Apply&& apply) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int k = 1; k <= 300; ++k) {
    ImuReading imu;
    imu.b_acc_mps2 = Vec3(0.3 * n(rng), 0.3 * n(rng), kGravity_mps2 + 0.3 * n(rng));
    imu.b_gyro_radps = 0.05 * Vec3(n(rng), n(rng), n(rng));
    apply(imu, 0.001, nullptr);
    if (k % 3 == 0) {
      const int a = (k / 3) % 8, b = (k / 3 + 1) % 8;
      const TdoaMeasurement z{k * 0.001, a, b, 0.8 * std::sin(0.1 * k) + 0.1 * n(rng)};
      apply(imu, 0.0, &z);
    }
  }
}

TEST(StartReplay, ReplayIsTheFilterRunFromTheRestartedState) {
  // GIVEN a filter at the reference instant (with range-bias states) and a record of a window's predictions and TDoA
  EkfParams params;
  const AnchorTable anchors = filtertest::arenaAnchors();
  TdoaUpdateOptions opt;
  opt.gate_sigma = 0.0;
  Ekf at_ref(params);
  ErrMat P0 = initialCovariance(params);
  at_ref.initialize(movingState(), P0);
  StartReplay replay(params);
  replay.begin(at_ref, 2.0);
  EXPECT_TRUE(replay.recording());
  EXPECT_DOUBLE_EQ(replay.referenceTime(), 2.0);
  windowEvents([&](const ImuReading& imu, double dt, const TdoaMeasurement* z) {
    if (z) replay.recordTdoa(*z);
    else replay.recordPredict(imu, dt);
  });
  // WHEN it is replayed from p0, v0 with a wide prior, and the same events are run by hand on that restarted filter
  const Vec3 p0(0.7, -0.1, 1.0), v0(0.2, 0.1, -0.1);
  const double sp = 0.3, sv = 1.0, period = params.cov_period_s;
  Ekf replayed(params);
  const auto update = [&](Ekf& f, const TdoaMeasurement& z) { updateTdoa(f, anchors, z, opt); };
  ASSERT_TRUE(replay.replay(replayed, p0, v0, sp, sv, period, update));
  Ekf by_hand = at_ref;
  by_hand.propagateCovariance();
  Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Zero();
  cov.diagonal() << sp * sp, sp * sp, sp * sp, sv * sv, sv * sv, sv * sv;
  by_hand.resetPositionVelocity(p0, v0, cov);
  windowEvents([&](const ImuReading& imu, double dt, const TdoaMeasurement* z) {
    if (!z) {
      by_hand.predict(imu, dt);
      return;
    }
    if (by_hand.pendingDt() >= period) by_hand.propagateCovariance();
    update(by_hand, *z);
  });
  by_hand.propagateCovariance();
  // THEN both end in the same state and covariance, range biases included, and the record has ended
  EXPECT_LT((replayed.state().w_p_b - by_hand.state().w_p_b).norm(), 1e-12);
  EXPECT_LT((replayed.state().w_v_b - by_hand.state().w_v_b).norm(), 1e-12);
  EXPECT_LT((replayed.covariance() - by_hand.covariance()).cwiseAbs().maxCoeff(), 1e-12);
  ASSERT_TRUE(replayed.rangeBias() && by_hand.rangeBias());
  EXPECT_LT((replayed.rangeBias()->covariance() - by_hand.rangeBias()->covariance()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_FALSE(replay.recording());
  // the TDoA moved the state away from the restart point: the run is not the restart alone
  EXPECT_GT((replayed.state().w_p_b - p0).norm(), 1e-3);
}

TEST(StartReplay, AStoppedOrOverflowedRecordIsNotReplayed) {
  EkfParams params;
  Ekf f(params);
  f.initialize(movingState(), initialCovariance(params));
  const auto no_update = [](Ekf&, const TdoaMeasurement&) {};
  Ekf target(params);
  target.initialize(NavState{}, initialCovariance(params));
  // stopped
  StartReplay stopped(params);
  stopped.begin(f, 0.0);
  stopped.recordPredict(ImuReading{}, 0.001);
  stopped.stop();
  EXPECT_FALSE(stopped.replay(target, Vec3::Ones(), Vec3::Zero(), 0.3, 1.0, 0.0, no_update));
  // overflowed: capacity 4, five entries
  StartReplay small(params, 4);
  small.begin(f, 0.0);
  for (int k = 0; k < 5; ++k) small.recordPredict(ImuReading{}, 0.001);
  EXPECT_FALSE(small.replay(target, Vec3::Ones(), Vec3::Zero(), 0.3, 1.0, 0.0, no_update));
  EXPECT_FALSE(small.recording());
  // the target is untouched either way
  EXPECT_EQ(target.state().w_p_b, Vec3::Zero());
  // a record that fits is replayed
  StartReplay fits(params, 4);
  fits.begin(f, 0.0);
  for (int k = 0; k < 4; ++k) fits.recordPredict(ImuReading{}, 0.001);
  EXPECT_TRUE(fits.replay(target, Vec3::Ones(), Vec3::Zero(), 0.3, 1.0, 0.0, no_update));
  EXPECT_NEAR(target.state().w_p_b.x(), 1.0, 1e-3);
}

TEST(StartReplay, AStartInTheAirIsReplayedAndAStartOnTheFloorIsNot) {
  // GIVEN a body cruising at 0.8 m/s along x at 1.2 m from the first sample on, and the same anchors, and a body
  // that sits on the floor for the first seconds
  const AnchorTable anchors = filtertest::arenaAnchors();
  const auto cruise = [](double t) {
    return filtertest::Truth{Vec3(-1.5 + 0.8 * t, 0.5, 1.2), Vec3(0.8, 0, 0), Vec3::Zero()};
  };
  const SensorLog air = filtertest::flightLog(anchors, cruise, 0.0, 6.0, 0.05, true, 11);
  filtertest::TakeoffLogSpec spec;
  const SensorLog ground = filtertest::takeoffLog(spec);
  for (const bool replay : {true, false}) {
    EkfParams p;
    p.start_replay = replay;
    const TdoaLocalizer loc(p, anchors);
    // WHEN each is localized
    const LocalizerResult r_air = loc.run(air, 0.01);
    const LocalizerResult r_ground = loc.run(ground, 0.01);
    // THEN only the start in the air runs the window again, and only when asked to
    EXPECT_EQ(r_air.summary.start_replayed, replay);
    EXPECT_FALSE(r_ground.summary.start_replayed);
    // and with the replay the velocity 1 s after the fix is the cruise's within 0.2 m/s
    if (replay) {
      const double t_check = r_air.summary.ready_t_s + 1.0;
      int n_checked = 0;
      for (const LocalizerEstimate& e : r_air.estimates) {
        if (std::abs(e.t_s - t_check) >= 0.005) continue;
        EXPECT_LT((e.x.w_v_b - Vec3(0.8, 0, 0)).norm(), 0.2) << "t = " << e.t_s;
        ++n_checked;
      }
      EXPECT_GT(n_checked, 0);
    }
  }
}

}  // namespace
}  // namespace uwb
