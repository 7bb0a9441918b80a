/** @file TofUpdateTest.cpp
 *  @brief Downward ToF height update (docs/math/filter.md F21): the measurement function and its Jacobian against
 *         central differences on the error state, tilt and range limits, merging of the ToF stream (F17), and on a
 *         synthetic flight with height-biased TDoA: ToF fusion fixes the height, invalid readings are ignored and
 *         counted, and with fuse_tof off the filter output does not change.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "support/TestSupport.h"
#include "uwb/filter/QuadImuProcess.h"
#include "FilterTestUtil.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/filter/TofUpdate.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

NavState tiltedState() {
  NavState x;
  x.w_p_b = Vec3(0.3, -0.7, 1.42);
  x.w_v_b = Vec3(0.5, 0.2, -0.1);
  x.w_q_b = Quat(Eigen::AngleAxisd(0.7, Vec3::UnitZ()) * Eigen::AngleAxisd(0.2, Vec3::UnitY()) *
                 Eigen::AngleAxisd(-0.15, Vec3::UnitX()));
  x.b_acc_bias = Vec3(0.01, -0.02, 0.05);
  x.b_gyro_bias = Vec3(0.001, 0.002, -0.001);
  return x;
}

TEST(TofUpdate, JacobianMatchesCentralDifferencesOnTheErrorState) {
  // GIVEN a tilted state 1.4 m above a floor at z = 0.1 and a sensor 0.037 m below the body origin
  const NavState x = tiltedState();
  const double offset_m = 0.037, floor_z_m = 0.1;
  // WHEN we evaluate the analytic Jacobian (F21) and the central difference of h(x ⊞ δx) at δx = 0
  ErrRow J;
  ASSERT_TRUE(tofPredictedRange(x, offset_m, floor_z_m, &J));
  const auto h = [&](const VecX& dx) {
    VecX out(1);
    out(0) = *tofPredictedRange(boxPlus(x, ErrVec(dx)), offset_m, floor_z_m);
    return out;
  };
  const test::JacobianCheck c = test::checkJacobian(h, VecX::Zero(kDim), J);
  // THEN they agree, and only δp_z and δθ enter
  EXPECT_LT(c.relative_error, 1e-6) << c;
  EXPECT_EQ(J.segment<3>(kVel).norm(), 0.0);
  EXPECT_EQ(J.segment<6>(kAccBias).norm(), 0.0);
  EXPECT_NE(J.segment<3>(kAtt).norm(), 0.0);
}

TEST(TofUpdate, LevelRangeIsHeightMinusOffsetAndTiltLengthensIt) {
  // GIVEN a level body 1.5 m above the floor
  NavState x;
  x.w_p_b = Vec3(0.0, 0.0, 1.5);
  // THEN the range is the height minus the sensor offset, and ∂h/∂p_z = 1
  ErrRow J;
  EXPECT_NEAR(*tofPredictedRange(x, 0.037, 0.0, &J), 1.463, 1e-12);
  EXPECT_NEAR(J(kPos + 2), 1.0, 1e-12);
  // AND rolled by 30°, the ray is 1/cos(30°) longer (Crazyflie kalmanCoreUpdateWithTof)
  x.w_q_b = Quat(Eigen::AngleAxisd(M_PI / 6.0, Vec3::UnitX()));
  EXPECT_NEAR(*tofPredictedRange(x, 0.037, 0.0), 1.5 / std::cos(M_PI / 6.0) - 0.037, 1e-12);
}

TEST(TofUpdate, NearlyHorizontalSensorIsDegenerateAndLeavesTheFilterUnchanged) {
  // GIVEN a body rolled by 90° (the sensor looks sideways)
  Ekf ekf(EkfParams{});
  NavState x;
  x.w_p_b = Vec3(0.0, 0.0, 1.0);
  x.w_q_b = Quat(Eigen::AngleAxisd(M_PI / 2.0, Vec3::UnitX()));
  ekf.initialize(x, initialCovariance(EkfParams{}));
  // WHEN a ToF reading arrives
  EXPECT_FALSE(tofPredictedRange(x, 0.037, 0.0));
  const TofUpdateResult r = updateTof(ekf, 1.0, TofUpdateOptions{});
  // THEN nothing is applied
  EXPECT_EQ(r.outcome, UpdateOutcome::kDegenerate);
  EXPECT_EQ(ekf.state().w_p_b, x.w_p_b);
}

TEST(TofUpdate, InvalidReadingsAreSkippedAndOutliersGated) {
  // GIVEN a level filter at 1 m with 5 cm height std
  EkfParams params;
  Ekf ekf(params);
  NavState x;
  x.w_p_b = Vec3(0.0, 0.0, 1.0);
  ErrMat P = initialCovariance(params);
  P.block<3, 3>(kPos, kPos) = Mat3::Identity() * 0.05 * 0.05;
  ekf.initialize(x, P);
  TofUpdateOptions opt;
  // THEN NaN, negative, zero and above-range readings are skipped
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), -0.2, 0.0, 3.6, 8.19})
    EXPECT_EQ(updateTof(ekf, bad, opt).outcome, UpdateOutcome::kSkipped) << bad;
  // AND a reading 1 m off is rejected by the χ² gate, while a plausible one is applied
  EXPECT_EQ(updateTof(ekf, 1.963 + 1.0, opt).outcome, UpdateOutcome::kRejectedOutlier);
  EXPECT_EQ(ekf.state().w_p_b.z(), 1.0);
  const TofUpdateResult ok = updateTof(ekf, 0.963 + 0.02, opt);
  EXPECT_EQ(ok.outcome, UpdateOutcome::kApplied);
  EXPECT_GT(ekf.state().w_p_b.z(), 1.0);
}

TEST(SensorEvents, TofStreamIsMergedAfterImuAndTdoaAtEqualStamps) {
  // GIVEN IMU, TDoA and ToF samples, ToF out of order and with one non-finite stamp
  SensorLog log;
  log.imu = {{0.0, {}}, {0.01, {}}, {0.02, {}}};
  log.tdoa = {{0.01, 0, 1, 0.5}};
  log.tof = {{0.015, 1.0}, {0.01, 1.1}, {std::numeric_limits<double>::quiet_NaN(), 1.2}};
  // WHEN merging
  MergeReport rep;
  const std::vector<SensorEvent> ev = mergeSensorStreams(log, 0.2, &rep);
  // THEN the ToF events are in time order, after IMU and TDoA at equal stamps, and the bad stamp is counted
  ASSERT_EQ(ev.size(), 6u);
  EXPECT_EQ(ev[1].kind, SensorEvent::Kind::kImu);
  EXPECT_EQ(ev[2].kind, SensorEvent::Kind::kTdoa);
  EXPECT_EQ(ev[3].kind, SensorEvent::Kind::kTof);
  EXPECT_EQ(log.tof[ev[3].index].range_m, 1.1);
  EXPECT_EQ(ev[4].kind, SensorEvent::Kind::kTof);
  EXPECT_EQ(ev[5].kind, SensorEvent::Kind::kImu);
  EXPECT_EQ(rep.n_tof_in, 3u);
  EXPECT_EQ(rep.n_tof_out_of_order, 1u);
  EXPECT_EQ(rep.n_nonfinite, 1u);
}

// ----------------------------------------------------------------------------- synthetic flight
using filtertest::arenaAnchors;
const auto vertical = filtertest::takeoffProfile;

constexpr double kTofOffset_m = 0.037;

/// IMU 1 kHz, TDoA 400 Hz generated as if the tag were tdoa_dz_m higher than it is (a height bias as the
/// position-dependent UWB bias produces), ToF 25 Hz with 1 cm noise.
SensorLog makeLog(double tdoa_dz_m, double duration_s, unsigned seed) {
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = duration_s;
  spec.tdoa_dz = [=](double t) { return t > 2.0 ? tdoa_dz_m : 0.0; };
  std::mt19937 rng(seed);
  SensorLog log = filtertest::takeoffLog(spec, rng);
  std::normal_distribution<double> n(0.0, 1.0);
  // (a real sensor reports no negative range: clamp the noisy 13 mm on the floor)
  for (double t = 0.0; t <= duration_s; t += 0.04)
    log.tof.push_back({t, std::max(0.005, vertical(t).z - kTofOffset_m + 0.01 * n(rng))});
  return log;
}

/// RMS of (estimated − true) height over [t0, t1].
double heightRmse(const LocalizerResult& r, double t0, double t1) {
  double sum = 0.0;
  int n = 0;
  for (const LocalizerEstimate& e : r.estimates)
    if (e.t_s >= t0 && e.t_s <= t1) {
      const double d = e.x.w_p_b.z() - vertical(e.t_s).z;
      sum += d * d;
      ++n;
    }
  return n ? std::sqrt(sum / n) : std::nan("");
}

TEST(TofLocalizer, FusionCorrectsTheHeightUnderHeightBiasedTdoa) {
  // GIVEN a flight whose TDoA put the drone 0.3 m too high, and a ToF stream
  const SensorLog log = makeLog(0.3, 12.0, 5);
  EkfParams on;  // the default fuses the range when the log has it (F21)
  EkfParams off = on;
  off.fuse_tof = false;
  // WHEN localizing with and without ToF fusion
  const LocalizerResult r_off = TdoaLocalizer(off, arenaAnchors()).run(log);
  const LocalizerResult r_on = TdoaLocalizer(on, arenaAnchors()).run(log);
  ASSERT_FALSE(std::isnan(r_on.summary.takeoff_t_s));
  // THEN in the hover the height error is the TDoA bias without ToF and a few cm with it
  const double e_off = heightRmse(r_off, 6.0, 12.0);
  const double e_on = heightRmse(r_on, 6.0, 12.0);
  EXPECT_GT(e_off, 0.2);
  EXPECT_LT(e_on, 0.05) << "without ToF " << e_off;
  EXPECT_GT(r_on.summary.n_tof_used, 150u);
  EXPECT_EQ(r_off.summary.n_tof_used, 0u);
}

TEST(TofLocalizer, InvalidAndOutOfRangeReadingsAreIgnoredAndCounted) {
  // GIVEN the flight with every 5th ToF reading replaced by NaN, a negative value or one beyond 3.5 m
  const SensorLog clean = makeLog(0.3, 10.0, 6);
  SensorLog dirty = clean;
  SensorLog valid_only = clean;
  valid_only.tof.clear();
  std::size_t n_bad = 0;
  const double bad_values[3] = {std::numeric_limits<double>::quiet_NaN(), -1.0, 8.19};
  for (std::size_t i = 0; i < dirty.tof.size(); ++i) {
    if (i % 5 == 0) {
      dirty.tof[i].range_m = bad_values[n_bad++ % 3];
    } else {
      valid_only.tof.push_back(dirty.tof[i]);
    }
  }
  EkfParams on;
  on.fuse_tof = true;
  // WHEN localizing the dirty stream and the stream of its valid readings only
  const LocalizerResult r_dirty = TdoaLocalizer(on, arenaAnchors()).run(dirty);
  const LocalizerResult r_valid = TdoaLocalizer(on, arenaAnchors()).run(valid_only);
  // THEN the invalid readings are counted, and ignored: the estimates are the same
  EXPECT_EQ(r_dirty.summary.n_tof_invalid, n_bad);
  EXPECT_EQ(r_dirty.summary.n_tof_total, dirty.tof.size());
  EXPECT_EQ(r_valid.summary.n_tof_invalid, 0u);
  EXPECT_EQ(r_dirty.summary.n_tof_used, r_valid.summary.n_tof_used);
  ASSERT_EQ(r_dirty.estimates.size(), r_valid.estimates.size());
  for (std::size_t i = 0; i < r_dirty.estimates.size(); ++i)
    ASSERT_EQ(r_dirty.estimates[i].x.w_p_b, r_valid.estimates[i].x.w_p_b) << "at " << r_dirty.estimates[i].t_s;
  // AND readings before the position is known are not used
  EXPECT_GT(r_dirty.summary.n_tof_not_ready, 0u);
}

TEST(TofLocalizer, OffLeavesTheEstimatesUnchangedAndALogWithoutItIsUnchangedByDefault) {
  // GIVEN a log with and without the ToF stream
  const SensorLog with_tof = makeLog(0.3, 8.0, 7);
  SensorLog without_tof = with_tof;
  without_tof.tof.clear();
  // WHEN running the filter with fuse_tof off (`--no-tof`), and the default (on) on the log without the stream
  EkfParams off;
  off.fuse_tof = false;
  EkfParams defaults;
  ASSERT_TRUE(defaults.fuse_tof);
  const LocalizerResult a = TdoaLocalizer(off, arenaAnchors()).run(with_tof);
  const LocalizerResult b = TdoaLocalizer(off, arenaAnchors()).run(without_tof);
  const LocalizerResult c = TdoaLocalizer(defaults, arenaAnchors()).run(without_tof);
  // THEN the outputs are identical: off ignores the stream, and on uses nothing a log does not hold
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  ASSERT_EQ(b.estimates.size(), c.estimates.size());
  for (std::size_t i = 0; i < a.estimates.size(); ++i) {
    ASSERT_EQ(a.estimates[i].x.w_p_b, b.estimates[i].x.w_p_b);
    ASSERT_EQ(b.estimates[i].x.w_p_b, c.estimates[i].x.w_p_b);
  }
  EXPECT_EQ(a.summary.n_tof_used, 0u);
  EXPECT_GT(a.summary.n_tof_total, 0u);
}

TEST(EkfParams, TofFieldsAreValidated) {
  EkfParams p;
  p.fuse_tof = true;
  EXPECT_NO_THROW(p.validate());
  for (auto set : {+[](EkfParams& q) { q.tof_sigma_m = 0.0; }, +[](EkfParams& q) { q.tof_max_range_m = -1.0; },
                   +[](EkfParams& q) { q.tof_offset_m = std::nan(""); },
                   +[](EkfParams& q) { q.floor_z_m = std::numeric_limits<double>::infinity(); }}) {
    EkfParams q = p;
    set(q);
    EXPECT_THROW(q.validate(), std::invalid_argument);
  }
}

}  // namespace
}  // namespace uwb
