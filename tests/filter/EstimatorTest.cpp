/** @file EstimatorTest.cpp
 *  @brief The online estimator and its components on synthetic flights: the batch path equals the online loop,
 *         starts in motion (F16b) and on the floor (F16c), rest and contact evidence (F18), time jumps and
 *         re-acquisition (F16, F17), the floor (F22) and the reported covariance (F23).
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "FilterTestUtil.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/Multilateration.h"
#include "uwb/filter/RestDetector.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {
namespace {

using filtertest::arenaAnchors;

/// A body flying a horizontal circle (r = 1 m, 0.8 rad/s) at 1.4 m around (0.5, 0): position, velocity, acceleration.
filtertest::Truth circle(double t) {
  const double w = 0.8, r = 1.0;
  return {Vec3(0.5 + r * std::cos(w * t), r * std::sin(w * t), 1.4),
          Vec3(-r * w * std::sin(w * t), r * w * std::cos(w * t), 0.0),
          Vec3(-r * w * w * std::cos(w * t), -r * w * w * std::sin(w * t), 0.0)};
}

/// IMU (1 kHz, level body, rotor vibration) and TDoA (400 Hz, neighbour pairs) of the circle flight over [t0, t1].
SensorLog circleLog(double t0, double t1, unsigned seed, double tdoa_sigma_m = 0.05) {
  return filtertest::flightLog(arenaAnchors(), circle, t0, t1, tdoa_sigma_m, true, seed, {}, 0.05);
}

EkfParams lateralFullParams() {
  EkfParams p;
  p.accel_model = AccelModel::kFull;  // the synthetic IMU carries the horizontal acceleration
  return p;
}

/// RMS position error against the circle from t0_s on.
double circleRmsFrom(const LocalizerResult& r, double t0_s) {
  double se = 0.0;
  int n = 0;
  for (const LocalizerEstimate& e : r.estimates)
    if (e.t_s >= t0_s) se += (e.x.w_p_b - circle(e.t_s).p).squaredNorm(), ++n;
  return std::sqrt(se / n);
}

/// TdoaLocalizer::run on `log` over the arena's anchors, an estimate every 0.1 s, with the bias model when given.
LocalizerResult runInArena(const EkfParams& params, const SensorLog& log, const BiasPredictor& bias = {}) {
  return TdoaLocalizer(params, arenaAnchors(), bias).run(log, 0.1);
}

/// The position RMSE against the circle from 20 s on (circleRmsFrom).
double circleRms(const LocalizerResult& r) { return circleRmsFrom(r, 20.0); }

TEST(Estimator, BatchRunEqualsTheOnlineLoop) {
  // GIVEN a synthetic take-off log and the default parameters
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = 6.0;
  const SensorLog log = filtertest::takeoffLog(spec);
  const EkfParams p;
  // WHEN the batch path runs with one output per event, and the same events are pushed one at a time
  const LocalizerResult batch = TdoaLocalizer(p, arenaAnchors()).run(log, 0.0);
  Estimator online(p, arenaAnchors());
  std::vector<LocalizerEstimate> out;
  SensorEventCursor cursor(log);
  for (SensorEvent ev; cursor.next(ev);) {
    if (ev.kind == SensorEvent::Kind::kImu) online.addImu(ev.t_s, log.imu[ev.index].imu);
    else online.addTdoa(log.tdoa[ev.index]);
    if (online.ready()) out.push_back(online.estimate());
  }
  // THEN every output is the same, bit for bit, in the same number
  ASSERT_GT(batch.estimates.size(), 1000u);
  ASSERT_EQ(out.size(), batch.estimates.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].x.w_p_b, batch.estimates[i].x.w_p_b) << i;
    EXPECT_EQ(out[i].x.w_q_b.coeffs(), batch.estimates[i].x.w_q_b.coeffs()) << i;
    EXPECT_EQ(out[i].sigma_p_m, batch.estimates[i].sigma_p_m) << i;
  }
  EXPECT_EQ(online.summary().n_tdoa_used, batch.summary.n_tdoa_used);
}

TEST(Estimator, StartsInTheAirWithUnknownVelocity) {
  // GIVEN a log that begins while the body circles at 0.8 m/s (no ground phase, no start position)
  const SensorLog log = circleLog(3.0, 13.0, 7);
  // WHEN localizing with the defaults
  const LocalizerResult r = TdoaLocalizer(lateralFullParams(), arenaAnchors()).run(log);
  // THEN the position is found within a second and is within 0.3 m from 3 s after the first TDoA on
  ASSERT_FALSE(r.estimates.empty());
  EXPECT_LT(r.summary.ready_t_s, 3.0 + 1.0);
  double worst = 0.0;
  for (const LocalizerEstimate& e : r.estimates)
    if (e.t_s > 3.0 + 3.0) worst = std::max(worst, (e.x.w_p_b - circle(e.t_s).p).norm());
  EXPECT_LT(worst, 0.3);
  // and at least 90 % of the TDoA were used, gated or went into the start-up
  const LocalizerSummary& s = r.summary;
  EXPECT_GE(static_cast<double>(s.n_tdoa_used + s.n_tdoa_rejected + s.n_tdoa_start), 0.9 * s.n_tdoa_total);
  EXPECT_EQ(s.n_reacquisitions, 0u);
}

/// Tilt of the body z axis from the world vertical [rad].
double tiltOf(const Quat& w_q_b) { return std::acos(std::clamp((w_q_b * Vec3::UnitZ()).z(), -1.0, 1.0)); }

TEST(Estimator, StartInMotionUnderTheThrustModelIsLevelWhateverTheLateralReadings) {
  // GIVEN the circle log (a level body) whose accelerometer also reads a steady lateral offset of 0.4 g in x and
  // 0.2 g in y, as a Crazyflie's does in flight; the thrust model leaves those readings unused (F3)
  SensorLog log = circleLog(3.0, 8.0, 5);
  for (auto& s : log.imu) s.imu.b_acc_mps2 += Vec3(-0.4 * kGravity_mps2, -0.2 * kGravity_mps2, 0.0);
  // WHEN the filter starts in motion under the thrust model (the default) and under the full model
  const LocalizerResult thrust = TdoaLocalizer(EkfParams{}, arenaAnchors()).run(log);
  const LocalizerResult full = TdoaLocalizer(lateralFullParams(), arenaAnchors()).run(log);
  ASSERT_FALSE(thrust.estimates.empty());
  ASSERT_FALSE(full.estimates.empty());
  // THEN under the thrust model the attitude at the first fix is level, as the body is (F15); levelled from the
  // specific force it would be tilted by atan(0.45) = 0.42 rad
  EXPECT_LT(tiltOf(thrust.estimates.front().x.w_q_b), 0.05);
  // and under the full model, where the x/y readings are specific force, the tilt follows them
  EXPECT_GT(tiltOf(full.estimates.front().x.w_q_b), 0.3);
}

TEST(Estimator, RecoversFromATimeJumpInAllStreams) {
  // GIVEN the circle log with every stamp after t = 8 s moved 5 s later (a clock jump), the truth moved with it
  SensorLog log = circleLog(0.0, 14.0, 9);
  for (auto& s : log.imu)
    if (s.t_s > 8.0) s.t_s += 5.0;
  for (auto& s : log.tdoa)
    if (s.t_s > 8.0) s.t_s += 5.0;
  // WHEN localizing
  const LocalizerResult r = TdoaLocalizer(lateralFullParams(), arenaAnchors()).run(log);
  // THEN the jump is seen, and 3 s after it the estimate is back within 0.3 m of the truth
  EXPECT_GE(r.summary.n_time_jumps, 1u);
  double worst = 0.0;
  for (const LocalizerEstimate& e : r.estimates)
    if (e.t_s > 13.0 + 3.0) worst = std::max(worst, (e.x.w_p_b - circle(e.t_s - 5.0).p).norm());
  EXPECT_LT(worst, 0.3);
}

/// Worst position error of the estimates in [t0, t1) against the circle.
double worstCircleError(const LocalizerResult& r, double t0_s, double t1_s) {
  double worst = 0.0;
  for (const LocalizerEstimate& e : r.estimates)
    if (e.t_s >= t0_s && e.t_s < t1_s) worst = std::max(worst, (e.x.w_p_b - circle(e.t_s).p).norm());
  return worst;
}

/// Every TDoA with a stamp in (t0, t1) replaced by uniform garbage in [−10, 10] m.
void garbleTdoa(SensorLog& log, double t0_s, double t1_s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  for (auto& z : log.tdoa)
    if (z.t_s > t0_s && z.t_s < t1_s) z.tdoa_m = u(rng);
}

TEST(Estimator, ReacquiresAfterGarbageTdoa) {
  // GIVEN the circle log with 2 s of uniformly random TDoA in [−10, 10] m
  SensorLog log = circleLog(0.0, 16.0, 3);
  garbleTdoa(log, 6.0, 8.0, 5);
  // WHEN localizing
  const LocalizerResult r = TdoaLocalizer(lateralFullParams(), arenaAnchors()).run(log);
  // THEN 3 s after the garbage the estimate is within 0.3 m again
  EXPECT_LT(worstCircleError(r, 11.0, 1e300), 0.3);
}

TEST(Estimator, LongGarbageBurstIsDetectedByItsRejectionRateAndReacquired) {
  // GIVEN the circle log with 5 s of uniformly random TDoA in [−10, 10] m: some pass the gate, which widens as the
  // covariance grows, so the "nothing accepted" test of F16 alone does not fire
  SensorLog log = circleLog(0.0, 18.0, 4);
  garbleTdoa(log, 6.0, 11.0, 6);
  // WHEN localizing with the rejection-rate test (F16d) and without it
  const LocalizerResult on = TdoaLocalizer(lateralFullParams(), arenaAnchors()).run(log);
  EkfParams p_off = lateralFullParams();
  p_off.max_rejection_rate = 1.0;
  const LocalizerResult off = TdoaLocalizer(p_off, arenaAnchors()).run(log);
  // THEN it fires within 0.5 s of the burst's start, the estimate stays within the circle's reach (r = 1 m, plus the
  // relaxed velocity's v τ = 0.8 m, F16e) while lost, and is back within 0.3 m 3 s after the burst (the search keeps
  // its reference near the prediction, F16)
  EXPECT_GE(on.summary.n_rejection_faults, 1u);
  EXPECT_EQ(on.summary.n_reverted_motion, on.summary.n_rejection_faults);  // back to the motion before the burst
  ASSERT_FALSE(on.summary.reacquisition_t_s.empty());
  EXPECT_GT(on.summary.reacquisition_t_s.front(), 6.0);
  EXPECT_LT(on.summary.reacquisition_t_s.front(), 6.5);
  EXPECT_EQ(off.summary.n_rejection_faults, 0u);
  EXPECT_LT(worstCircleError(on, 14.0, 18.0), 0.3);
  EXPECT_LT(worstCircleError(on, 6.0, 11.0), 2.0 + 0.8 + 0.2);
}

TEST(Estimator, WithoutTdoaInFlightTheHorizontalMotionRelaxesInsteadOfDrifting) {
  // GIVEN the circle log without TDoA for 4 s, and an IMU whose horizontal acceleration is off by 1 m/s² meanwhile
  // (a tilt error of 6°: what the thrust model's horizontal channel rests on)
  SensorLog log = circleLog(0.0, 16.0, 8);
  std::erase_if(log.tdoa, [](const TdoaMeasurement& z) { return z.t_s > 6.0 && z.t_s < 10.0; });
  for (auto& s : log.imu)
    if (s.t_s > 6.0 && s.t_s < 10.0) s.imu.b_acc_mps2.x() += 1.0;
  // WHEN localizing with the relaxation (F16e) and without it
  const LocalizerResult relaxed = TdoaLocalizer(lateralFullParams(), arenaAnchors()).run(log);
  EkfParams p_off = lateralFullParams();
  p_off.lost_velocity_tau_s = 0.0;
  const LocalizerResult drifting = TdoaLocalizer(p_off, arenaAnchors()).run(log);
  // THEN after max_lost_s without TDoA the re-acquisition starts; the relaxed estimate stays within the circle's reach
  // (2r = 2 m) plus the first second's drift (0.5 m) and the relaxed velocity's (0.8 + 1) m/s · τ, while the IMU alone
  // drifts off by ½·1 m/s²·(4 s)² = 8 m; both are back 3 s after the outage
  ASSERT_FALSE(relaxed.summary.reacquisition_t_s.empty());
  EXPECT_NEAR(relaxed.summary.reacquisition_t_s.front(), 7.0, 0.1);
  EXPECT_LT(worstCircleError(relaxed, 6.0, 10.0), 2.0 + 0.5 + 1.8);
  EXPECT_GT(worstCircleError(drifting, 6.0, 10.0), 6.0);
  // and the reported σ covers the error while lost
  for (const LocalizerEstimate& e : relaxed.estimates) {
    if (e.t_s > 6.0 && e.t_s < 10.0) {
      EXPECT_LT((e.x.w_p_b - circle(e.t_s).p).head<2>().norm(), 3.0 * e.sigma_p_m.head<2>().norm()) << e.t_s;
    }
  }
  EXPECT_LT(worstCircleError(relaxed, 13.0, 16.0), 0.3);
  EXPECT_LT(worstCircleError(drifting, 13.0, 16.0), 0.3);
}

TEST(Estimator, GroundTdoaAreDownWeightedNotDropped) {
  // GIVEN a take-off log whose TDoA on the floor carry a height bias of +1 m (floor multipath) for 2 s
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = 10.0;
  spec.acc_noise_mps2 = 0.8;  // motors running (the frame shakes against the floor: floor_gyro_noise_radps)
  spec.tdoa_dz = [](double t) { return t < 2.0 ? 1.0 : 0.0; };
  // WHEN localizing
  const LocalizerResult r = TdoaLocalizer(EkfParams{}, arenaAnchors()).run(filtertest::takeoffLog(spec));
  // THEN the floor TDoA were used (down-weighted), the estimate stayed near the floor before the climb, and the
  // hover at the end is accurate
  EXPECT_GT(r.summary.n_tdoa_used_at_rest, 100u);
  for (const LocalizerEstimate& e : r.estimates) {
    if (e.t_s > 1.0 && e.t_s < 1.9) {
      EXPECT_LT(e.x.w_p_b.z(), 0.4) << e.t_s;
    }
  }
  const LocalizerEstimate& last = r.estimates.back();
  EXPECT_LT((last.x.w_p_b - Vec3(0.8, -0.5, 1.05)).norm(), 0.15);
  EXPECT_FALSE(std::isnan(r.summary.takeoff_t_s));
}

TEST(Estimator, AMotorsOffStartIsOnTheGroundBeforeItsFirstFix) {
  // GIVEN a log that begins with the motors off on the floor (a still IMU) whose floor TDoA carry a height bias of
  // +2.5 m (floor-level anchors seen along the floor), the take-off at 2 s
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = 10.0;
  spec.tdoa_dz = [](double t) { return t < 2.0 ? 2.5 : 0.0; };
  std::mt19937 rng(5);
  SensorLog log = filtertest::takeoffLog(spec, rng);
  std::normal_distribution<double> n(0.0, 1.0);
  for (TimedImu& s : log.imu) {
    if (s.t_s >= 1.95) continue;
    s.imu.b_acc_mps2 = Vec3(0, 0, kGravity_mps2) + 0.01 * Vec3(n(rng), n(rng), n(rng));
    s.imu.b_gyro_radps = 0.002 * Vec3(n(rng), n(rng), n(rng));
  }
  // WHEN localizing
  const LocalizerResult r = TdoaLocalizer(EkfParams{}, arenaAnchors()).run(log);
  // THEN rest is decided from the levelling window's moments (F18) before the first fix (≥ 0.6 s of TDoA), so the
  // start is one on the floor: not a start in the air at the TDoA's 2.5 m, from which rest, far above the floor,
  // would never have entered the ground and the take-off would never have been seen
  ASSERT_FALSE(r.summary.ground_entered_t_s.empty());
  EXPECT_LT(r.summary.ground_entered_t_s.front(), r.summary.ready_t_s);
  EXPECT_LT(r.summary.ground_entered_t_s.front(), 0.4);
  EXPECT_FALSE(r.summary.started_in_motion);
  EXPECT_FALSE(std::isnan(r.summary.takeoff_t_s));
  for (const LocalizerEstimate& e : r.estimates) {
    if (e.t_s > r.summary.ready_t_s && e.t_s < 1.9) {
      EXPECT_LT(e.x.w_p_b.z(), 0.3) << e.t_s;
    }
  }
  EXPECT_LT((r.estimates.back().x.w_p_b - Vec3(0.8, -0.5, 1.05)).norm(), 0.15);
}

TEST(Estimator, TheFlightModeSupervisorTakesItsParamsFromEkfParams) {
  // GIVEN a take-off flight, and EkfParams whose prior airborne shaking level (F29b) lies far above any level the
  // flight shows (the learned level never falls below its prior)
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = 6.0;
  const SensorLog log = filtertest::takeoffLog(spec);
  EkfParams raised;
  raised.flight_mode.air_shake_prior_ms = 3.0 * 3.0;
  // WHEN localizing with them and with the defaults
  const LocalizerResult with_raised = TdoaLocalizer(raised, arenaAnchors()).run(log);
  const LocalizerResult with_defaults = TdoaLocalizer(EkfParams{}, arenaAnchors()).run(log);
  // THEN the estimator's supervisor holds the given prior, and the defaults' level stays below it
  EXPECT_GE(with_raised.summary.air_shake_rms_radps, 3.0);
  EXPECT_LT(with_defaults.summary.air_shake_rms_radps, 3.0);
}

TEST(RestDetector, AStillWindowSeedsRestWithinTheHold) {
  // GIVEN a body still from its first sample, and the moments of its first 0.1 s
  std::mt19937 rng(6);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto still = [&] {
    ImuReading m;
    m.b_acc_mps2 += 0.02 * Vec3(n(rng), n(rng), n(rng));
    m.b_gyro_radps = Vec3(0.004, 0.0, -0.003) + 0.002 * Vec3(n(rng), n(rng), n(rng));
    return m;
  };
  Vec3 acc_sum = Vec3::Zero(), gyro_sum = Vec3::Zero();
  double acc_sq = 0.0, gyro_sq = 0.0;
  for (int k = 0; k < 100; ++k) {
    const ImuReading m = still();
    acc_sum += m.b_acc_mps2, gyro_sum += m.b_gyro_radps;
    acc_sq += m.b_acc_mps2.squaredNorm(), gyro_sq += m.b_gyro_radps.squaredNorm();
  }
  const Vec3 acc_mean = acc_sum / 100.0, gyro_mean = gyro_sum / 100.0;
  RestDetector seeded, plain;
  for (RestDetector* d : {&seeded, &plain}) {
    d->reset(still());
    EXPECT_TRUE(d->setGyroReference(gyro_mean));
  }
  seeded.seed(0.1, acc_sq / 100.0 - acc_mean.squaredNorm(), gyro_sq / 100.0,
              gyro_sq / 100.0 - gyro_mean.squaredNorm());
  // WHEN the still samples go on
  double t_rest_seeded = -1.0, t_rest_plain = -1.0;
  for (double t = 0.101; t < 2.0; t += 0.001) {
    const ImuReading m = still();
    seeded.update(t, m, 0.001);
    plain.update(t, m, 0.001);
    if (t_rest_seeded < 0.0 && seeded.atRest()) t_rest_seeded = t;
    if (t_rest_plain < 0.0 && plain.atRest()) t_rest_plain = t;
  }
  // THEN the seeded detector reads rest when the 0.2 s hold has passed; from reset() alone the statistics first
  // decay from 1 (≈ 0.7 s for the gyro's mean square)
  EXPECT_NEAR(t_rest_seeded, 0.1 + RestDetectorParams{}.min_hold_s, 0.005);
  EXPECT_GT(t_rest_plain, 0.6);
  // AND non-finite or negative moments are ignored
  RestDetector bad;
  bad.reset(still());
  bad.seed(0.1, -1.0, std::nan(""), 0.0);
  bad.update(0.101, still(), 0.001);
  EXPECT_FALSE(bad.stillNow());
}

TEST(Estimator, AQuietImuInAHoverHighAboveTheFloorIsNotTheGround) {
  // GIVEN a take-off to a hover at 1.05 m whose IMU reads as quiet as with the motors off for 3 s (an IMU logged at
  // 100 Hz or low-pass filtered loses the rotor vibration that tells a still hover from rest)
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = 12.0;
  std::mt19937 rng(3);
  SensorLog log = filtertest::takeoffLog(spec, rng);
  std::normal_distribution<double> n(0.0, 1.0);
  for (TimedImu& s : log.imu) {
    if (s.t_s < 6.0 || s.t_s > 9.0) continue;
    s.imu.b_acc_mps2 = Vec3(0, 0, kGravity_mps2) + 0.01 * Vec3(n(rng), n(rng), n(rng));
    s.imu.b_gyro_radps = 0.002 * Vec3(n(rng), n(rng), n(rng));
  }
  // WHEN localizing
  const LocalizerResult r = TdoaLocalizer(EkfParams{}, arenaAnchors()).run(log);
  // THEN the IMU reads as at rest, but the estimate, far above the floor, is not put on the ground (the floor
  // height, the ZUPT and the ground's TDoA weight): one rest period (the start), and the hover height holds
  RestDetector probe;
  bool quiet_seen = false;
  for (std::size_t i = 1; i < log.imu.size(); ++i) {
    probe.update(log.imu[i].t_s, log.imu[i].imu, log.imu[i].t_s - log.imu[i - 1].t_s);
    quiet_seen = quiet_seen || (log.imu[i].t_s > 6.0 && probe.atRest());
  }
  EXPECT_TRUE(quiet_seen);
  EXPECT_EQ(r.summary.n_rest_periods, 1u);
  double worst_dz = 0.0;
  for (const LocalizerEstimate& e : r.estimates)
    if (e.t_s > 5.0) worst_dz = std::max(worst_dz, std::abs(e.x.w_p_b.z() - 1.05));
  EXPECT_LT(worst_dz, 0.2);
}

TEST(Estimator, ReportedCovarianceAddsTheBiasFloor) {
  // GIVEN the circle flight, once with the bias floor of F23 and once without
  const SensorLog log = circleLog(0.0, 8.0, 2);
  EkfParams with = lateralFullParams();
  with.output_bias_sigma_m = 0.2;
  EkfParams without = with;
  without.output_bias_sigma_m = 0.0;
  const LocalizerResult a = runInArena(with, log);
  const LocalizerResult b = runInArena(without, log);
  // THEN the states are the same, the reported σ larger by at least σ_b · (smallest singular value of H)⁻¹
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  const LocalizerEstimate& ea = a.estimates.back();
  const LocalizerEstimate& eb = b.estimates.back();
  EXPECT_EQ(ea.x.w_p_b, eb.x.w_p_b);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(ea.sigma_p_m(k), eb.sigma_p_m(k));
    // |h| ≤ 2 for every pair, so (HᵀH)⁻¹ ≥ I/(4 m) with m = 8 pairs in view
    EXPECT_GE(ea.sigma_p_m(k) * ea.sigma_p_m(k), eb.sigma_p_m(k) * eb.sigma_p_m(k) + 0.04 / (4.0 * 8.0));
  }
  // and the pose covariance is symmetric with the position block matching σ
  EXPECT_LT((ea.cov_pose - ea.cov_pose.transpose()).norm(), 1e-12 * ea.cov_pose.norm());
  EXPECT_DOUBLE_EQ(std::sqrt(ea.cov_pose(2, 2)), ea.sigma_p_m.z());
}

TEST(Estimator, TheVerticalScaleActsOnTheBiasTermsHeightAlone) {
  // GIVEN the circle flight in the air, run without the bias term, with it as derived (s = 1) and with its vertical
  // part halved (s = 0.5, F23d)
  const SensorLog log = circleLog(0.0, 8.0, 2);
  EkfParams derived = lateralFullParams();
  derived.output_bias_sigma_m = 0.2;
  derived.output_bias_vertical_scale = 1.0;
  EkfParams halved = derived;
  halved.output_bias_vertical_scale = 0.5;
  EkfParams none = derived;
  none.output_bias_sigma_m = 0.0;
  const LocalizerResult a = runInArena(derived, log);
  const LocalizerResult b = runInArena(halved, log);
  const LocalizerResult c = runInArena(none, log);
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  ASSERT_EQ(a.estimates.size(), c.estimates.size());
  // THEN the estimate and the horizontal σ are unchanged, the bias term's vertical variance is s² of the derived one
  // (C ← S C S) and its horizontal–vertical covariance s of it
  const LocalizerEstimate &ea = a.estimates.back(), &eb = b.estimates.back(), &ec = c.estimates.back();
  EXPECT_EQ(ea.x.w_p_b, eb.x.w_p_b);
  EXPECT_DOUBLE_EQ(ea.sigma_p_m.x(), eb.sigma_p_m.x());
  EXPECT_DOUBLE_EQ(ea.sigma_p_m.y(), eb.sigma_p_m.y());
  const double bias_zz_derived = ea.cov_pose(2, 2) - ec.cov_pose(2, 2);
  const double bias_zz_halved = eb.cov_pose(2, 2) - ec.cov_pose(2, 2);
  ASSERT_GT(bias_zz_derived, 1e-4);
  EXPECT_NEAR(bias_zz_halved, 0.25 * bias_zz_derived, 1e-12);
  EXPECT_NEAR(eb.cov_pose(0, 2) - ec.cov_pose(0, 2), 0.5 * (ea.cov_pose(0, 2) - ec.cov_pose(0, 2)), 1e-12);
  EXPECT_LT(eb.sigma_p_m.z(), ea.sigma_p_m.z());
}

TEST(Estimator, ABiasModelOfAMoreBiasedFlightIsScaledDownByThisFlightsLevel) {
  // GIVEN a flight without TDoA bias (white noise 5 cm) and a bias model that does not fit it: ±0.3 m per pair, as a
  // model trained on flights whose measured bias level was 0.5 m might predict
  const SensorLog log = circleLog(0.0, 40.0, 3);
  const BiasPredictor wrong = [](const TdoaFeature& f) {
    BiasPrediction b;
    b.mean_m = (f.id_a + f.id_b) % 2 == 0 ? 0.3 : -0.3;
    b.variance_m2 = 0.01;
    return b;
  };
  EkfParams scaled = lateralFullParams();
  scaled.bias_model_training_level_m = 0.5;
  scaled.bias_guard = false;  // the corrected filter alone: the scaling (F24b) without the guard (F24) beside it
  EkfParams off = scaled;
  off.bias_model_level_exponent = 0.0;
  EkfParams unknown = scaled;
  unknown.bias_model_training_level_m = 0.0;  // an older model file
  const LocalizerResult a = runInArena(scaled, log, wrong);
  const LocalizerResult b = runInArena(off, log, wrong);
  const LocalizerResult c = runInArena(unknown, log, wrong);
  // THEN the flight's own level (measured before the correction, F24b) is far below the model's: it starts from the
  // training level (ρ = 1), which keeps the weight of 10 windows against the ≈ 50 windows of 40 s flown
  // (√((10 · 0.5²) / 60) ≈ 0.2 m even with no bias at all), the mean is scaled down by (0.2 / 0.5)² and below,
  // and the position error with it
  EXPECT_LT(a.summary.raw_bias_level_m, 0.25);
  EXPECT_LT(a.summary.bias_model_mean_scale, 0.25);
  EXPECT_LE(a.summary.min_bias_model_mean_scale, a.summary.bias_model_mean_scale);
  EXPECT_LT(circleRms(a), 0.5 * circleRms(b));
  // the model as trained when the scaling is off or the training level unknown: the same run
  EXPECT_EQ(b.summary.bias_model_mean_scale, 1.0);
  EXPECT_EQ(circleRms(b), circleRms(c));
  EXPECT_TRUE(std::isfinite(c.summary.raw_bias_level_m));  // still measured and reported
}

TEST(Estimator, ABiasModelThatPredictsThisFlightsSmallerBiasIsNotScaledDownForIt) {
  // GIVEN a flight whose TDoA carry a constant bias per pair, and a model that knows it exactly, trained on flights
  // with twice the bias: their level and the level of the model's mean on them were twice this flight's
  const auto bias = [](int pair) { return 0.2 * std::sin(1.7 * pair + 0.3); };
  const SensorLog log = filtertest::flightLog(arenaAnchors(), circle, 0.0, 40.0, 0.05, true, 3,
                                              [&](double, int pair) { return bias(pair); }, 0.05);
  const BiasPredictor knows = [&](const TdoaFeature& f) {
    BiasPrediction b;
    b.mean_m = bias(f.id_a);
    b.variance_m2 = 1e-4;
    return b;
  };
  // the two levels on this flight (F23c on the uncorrected TDoA and on µ), read from a run at its own levels
  EkfParams probe = lateralFullParams();
  probe.bias_model_training_level_m = 0.2;
  probe.bias_model_training_mean_level_m = 0.2;
  const LocalizerResult measured = runInArena(probe, log, knows);
  const double level = measured.summary.raw_bias_level_m, mean_level = measured.summary.model_mean_level_m;
  ASSERT_GT(level, 0.05);
  ASSERT_GT(mean_level, 0.05);
  EkfParams levels_only = lateralFullParams();  // F24b: the training flights' level alone
  levels_only.bias_model_training_level_m = 2.0 * level;
  EkfParams with_mean = levels_only;  // F24c: and what the model predicted there
  with_mean.bias_model_training_mean_level_m = 2.0 * mean_level;
  EkfParams as_trained = levels_only;
  as_trained.bias_model_level_exponent = 0.0;
  const LocalizerResult b = runInArena(levels_only, log, knows);
  const LocalizerResult c = runInArena(with_mean, log, knows);
  const LocalizerResult t = runInArena(as_trained, log, knows);
  // THEN the training level alone reads this flight as half as biased and halves the correction and more (F24b);
  // with the model's own level the ratio is about one: the model predicts here the smaller bias it sees, and is used
  // as trained (F24c)
  EXPECT_LT(b.summary.bias_model_mean_scale, 0.5);
  EXPECT_GT(c.summary.bias_model_mean_scale, 0.8);
  EXPECT_LT(c.summary.model_mean_level_m, 1.5 * mean_level);
  EXPECT_LT(circleRms(c), circleRms(b));
  EXPECT_LT(circleRms(c), 1.1 * circleRms(t));
  EXPECT_TRUE(std::isnan(b.summary.model_mean_level_m));  // not measured without the training mean level
}

TEST(Estimator, AFlightMoreBiasedThanTheModelsTrainingFlightsCanWidenTheCorrectedTdoa) {
  // GIVEN a flight whose TDoA carry a constant bias per pair, and a model that predicts none of it, trained on
  // flights of a quarter of this flight's level (their mean's level unknown)
  const auto bias = [](int pair) { return 0.2 * std::sin(1.7 * pair + 0.3); };
  const SensorLog log = filtertest::flightLog(arenaAnchors(), circle, 0.0, 40.0, 0.05, true, 3,
                                              [&](double, int pair) { return bias(pair); }, 0.05);
  const BiasPredictor nothing = [](const TdoaFeature&) {
    BiasPrediction b;
    b.variance_m2 = 1e-4;
    return b;
  };
  EkfParams probe = lateralFullParams();
  probe.bias_model_training_level_m = 0.2;
  const double level = runInArena(probe, log, nothing).summary.raw_bias_level_m;
  ASSERT_GT(level, 0.05);
  EkfParams off = lateralFullParams();
  off.bias_model_training_level_m = 0.25 * level;
  EkfParams on = off;
  on.bias_model_level_variance = true;
  const LocalizerResult a = runInArena(off, log, nothing);
  const LocalizerResult b = runInArena(on, log, nothing);
  // THEN with F24e each corrected TDoA gains ℓ² − ℓ_train² (gp.md P43c) of the level measured so far (ℓ starts
  // from the training level and keeps its weight of 10 windows, F24b); without it nothing is added
  const double train = 0.25 * level;
  EXPECT_EQ(a.summary.bias_model_level_variance_m2, 0.0);
  ASSERT_GT(b.summary.raw_bias_level_m, 1.5 * train);
  EXPECT_NEAR(b.summary.bias_model_level_variance_m2,
              levelExcessVariance(b.summary.raw_bias_level_m, std::nan(""), train, 0.0), 1e-15);
  EXPECT_GT(b.summary.bias_model_level_variance_m2, train * train);
  EXPECT_NE(a.estimates.back().x.w_p_b, b.estimates.back().x.w_p_b);
  EXPECT_TRUE(std::isfinite(circleRmsFrom(b, 20.0)));
}

TEST(Estimator, OnTheFloorTheReportedCovarianceCarriesTheFloorLevelBias) {
  // GIVEN a take-off log (on the floor for 2 s, then a climb), localized with the bias floor of F23 and without it
  const SensorLog log = filtertest::takeoffLog(filtertest::TakeoffLogSpec{});
  EkfParams with;
  EkfParams without = with;
  without.output_bias_sigma_m = 0.0;
  const LocalizerResult a = TdoaLocalizer(with, arenaAnchors()).run(log, 0.05);
  const LocalizerResult b = TdoaLocalizer(without, arenaAnchors()).run(log, 0.05);
  ASSERT_EQ(a.estimates.size(), b.estimates.size());
  // THEN the states are the same; on the floor the added variance is the floor-level bias's, horizontal only and at
  // least that of the flight's σ_b, with the body's height on the floor (0.1 m) for z (F23′); in flight the anchor
  // biases' term of F23, which holds z too
  int n_floor = 0, n_air = 0;
  double min_floor_xy = 1e9, max_air_xy = 0.0;
  for (std::size_t i = 0; i < a.estimates.size(); ++i) {
    const LocalizerEstimate& ea = a.estimates[i];
    const LocalizerEstimate& eb = b.estimates[i];
    ASSERT_EQ(ea.x.w_p_b, eb.x.w_p_b);
    const Vec3 added = ea.sigma_p_m.cwiseAbs2() - eb.sigma_p_m.cwiseAbs2();
    if (ea.phase == FlightPhase::kGround && ea.t_s > 1.0) {
      ++n_floor;
      EXPECT_NEAR(added.z(), 0.1 * 0.1, 1e-9) << "t = " << ea.t_s;
      min_floor_xy = std::min(min_floor_xy, added.head<2>().minCoeff());
    } else if (ea.phase == FlightPhase::kTracking && ea.x.w_p_b.z() > 0.5) {
      ++n_air;
      EXPECT_GT(added.z(), 0.0);
      max_air_xy = std::max(max_air_xy, added.head<2>().maxCoeff());
    }
  }
  ASSERT_GT(n_floor, 5);
  ASSERT_GT(n_air, 5);
  EXPECT_GT(min_floor_xy, 4.0 * max_air_xy);  // σ_b on the floor 1.0 m (rest_tdoa_sigma_m) against 0.2 m in flight
}

TEST(RestDetector, RestIsDecidedAndRevisedFromTheImu) {
  RestDetector d;
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  ImuReading still;
  d.reset(still);
  double t = 0.0;
  // one phase of white IMU noise: accelerometer std acc_std, gyroscope std gyro_std per axis, until t_end
  const auto feed = [&](double t_end, double acc_std, double gyro_std, double* t_rest_ended = nullptr) {
    for (; t < t_end; t += 0.001) {
      ImuReading m;
      m.b_acc_mps2 += acc_std * Vec3(n(rng), n(rng), n(rng));
      m.b_gyro_radps = gyro_std * Vec3(n(rng), n(rng), n(rng));
      d.update(t, m, 0.001);
      if (t_rest_ended && !d.atRest() && *t_rest_ended < 0.0) *t_rest_ended = t;
    }
  };
  // GIVEN a still IMU for 1 s THEN it is at rest and not shaking
  feed(1.0, 0.01, 0.001);
  EXPECT_TRUE(d.atRest());
  EXPECT_FALSE(d.shaking());
  // WHEN the rotors spin up (vibration) THEN rest ends within 0.2 s
  double t_end = -1.0;
  feed(2.0, 1.0, 0.05, &t_end);
  EXPECT_LT(t_end - 1.0, 0.2);
  EXPECT_FALSE(d.shaking());  // flight-level gyro noise is not floor contact
  // WHEN the frame shakes against the floor THEN shaking is reported
  feed(2.5, 1.0, 0.5);
  EXPECT_TRUE(d.shaking());
}

TEST(RestDetector, AnUncalibratedGyroReadsAsRestAgainstItsReference) {
  // GIVEN a body at rest whose gyro carries a bias of 0.03 rad/s per axis (0.052 rad/s in norm, above the 0.03 rad/s
  // rms of the rest test; a raw MEMS gyro without the Crazyflie's start-up calibration)
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0.0, 1.0);
  const Vec3 bias(0.03, -0.03, 0.03);
  const auto still = [&](const Vec3& b) {
    ImuReading m;
    m.b_acc_mps2 += 0.01 * Vec3(n(rng), n(rng), n(rng));
    m.b_gyro_radps = b + 0.001 * Vec3(n(rng), n(rng), n(rng));
    return m;
  };
  const auto feed = [&](RestDetector& d, const Vec3& b, double seconds) {
    for (double t = 0.0; t < seconds; t += 0.001) d.update(t, still(b), 0.001);
  };
  RestDetector raw, referenced, wrong;
  for (RestDetector* d : {&raw, &referenced, &wrong}) d->reset(still(bias));
  // WHEN one detector has no reference, one the mean of a still window as its reference
  Vec3 mean = Vec3::Zero();
  for (int k = 0; k < 100; ++k) mean += still(bias).b_gyro_radps / 100.0;
  EXPECT_TRUE(referenced.setGyroReference(mean));
  feed(raw, bias, 1.0);
  feed(referenced, bias, 1.0);
  // THEN only the referenced one reads rest; the test on the raw rate alone is the same as without a reference
  EXPECT_FALSE(raw.atRest());
  EXPECT_TRUE(referenced.atRest());
  EXPECT_TRUE(referenced.hasGyroReference());
  // AND a reference of a turning body (0.5 rad/s) is refused, and a wrong one costs nothing: a calibrated gyro at
  // rest still reads rest on its raw rate
  EXPECT_FALSE(wrong.setGyroReference(Vec3(0.0, 0.0, 0.5)));
  EXPECT_FALSE(wrong.hasGyroReference());
  EXPECT_TRUE(wrong.setGyroReference(Vec3(0.05, 0.0, 0.0)));
  feed(wrong, Vec3::Zero(), 1.0);
  EXPECT_TRUE(wrong.atRest());
  // AND turning at 0.2 rad/s is not rest against either
  feed(referenced, Vec3(0.0, 0.0, 0.2), 1.0);
  EXPECT_FALSE(referenced.atRest());
}

TEST(RestDetector, StatisticsAreTheExponentialAveragesForAnyStepSequence) {
  // GIVEN IMU samples at a jittered period (steps repeat and change, as logged stamps do)
  RestDetector d;
  ImuReading first;
  first.b_acc_mps2 = Vec3(0.1, -0.2, 9.8);
  d.reset(first);
  const RestDetectorParams p;
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0.0, 0.3);
  const double steps[] = {0.001, 0.001, 0.0012, 0.001, 0.0008, 0.0008, 0.001};
  // WHEN fed, and the F18 averages are computed alongside with std::exp for every step
  double acc_mean = first.b_acc_mps2.norm(), acc_var = 1.0, gyro_ms = 1.0;
  double t = 0.0;
  for (int k = 0; k < 700; ++k) {
    const double dt = steps[k % 7];
    t += dt;
    ImuReading m;
    m.b_acc_mps2 = Vec3(n(rng), n(rng), 9.81 + n(rng));
    m.b_gyro_radps = 0.1 * Vec3(n(rng), n(rng), n(rng));
    d.update(t, m, dt);
    const double a = std::exp(-dt / p.tau_s), an = m.b_acc_mps2.norm();
    acc_mean = a * acc_mean + (1 - a) * an;
    acc_var = a * acc_var + (1 - a) * (an - acc_mean) * (an - acc_mean);
    gyro_ms = a * gyro_ms + (1 - a) * m.b_gyro_radps.squaredNorm();
  }
  // THEN the detector's statistics are those averages (its decay factors are recomputed only when the step changes)
  EXPECT_NEAR(d.accVariance(), acc_var, 1e-12 * acc_var);
  EXPECT_NEAR(d.gyroMeanSquare(), gyro_ms, 1e-12 * gyro_ms);
}

TEST(Multilateration, MovingSolveRecoversPositionAndVelocity) {
  // GIVEN noise-free TDoA of a body moving at (0.6, −0.4, 0.1) m/s from (0.3, 0.2, 1.2) for 0.6 s, with zero
  // predicted displacement (the filter knew nothing of the motion)
  const AnchorTable anchors = arenaAnchors();
  const Vec3 p0(0.3, 0.2, 1.2), v0(0.6, -0.4, 0.1);
  std::vector<MultilaterationSample> s;
  int k = 0;
  for (double t = 0.0; t <= 0.6; t += 0.0025, ++k) {
    const int a = k % 8, b = (k + 1) % 8;
    const Vec3 p_tag = tagPosition(p0 + t * v0, Quat::Identity(), kUtilTagOffset_b);
    MultilaterationSample m;
    m.z = {t, a, b, range(p_tag, anchors.find(b)->m) - range(p_tag, anchors.find(a)->m)};
    s.push_back(m);
  }
  const std::vector<Vec3> guesses = {Vec3(0, 0, 1.5)};
  // WHEN solving for position only and for position and velocity
  const auto still = multilaterate(s, anchors, kUtilTagOffset_b, guesses);
  const auto moving = multilaterateMoving(s, anchors, kUtilTagOffset_b, guesses, 0.0);
  // THEN the moving solve recovers both to a millimetre; the static one is off by about half the distance flown
  ASSERT_TRUE(moving && still);
  EXPECT_LT((moving->w_p0 - p0).norm(), 1e-3);
  EXPECT_LT((moving->w_v0 - v0).norm(), 1e-3);
  EXPECT_GT((still->w_p0 - p0).norm(), 0.1);
  // and too short a window is refused
  const std::vector<MultilaterationSample> shortw(s.begin(), s.begin() + 20);
  EXPECT_FALSE(multilaterateMoving(shortw, anchors, kUtilTagOffset_b, guesses, 0.0));
}

TEST(Multilateration, OnTheFloorOnlyXAndYAreSolved) {
  // GIVEN TDoA of a body on the floor whose height they overstate by 1 m (floor multipath)
  const AnchorTable anchors = arenaAnchors();
  const Vec3 p(1.0, -1.5, 0.03);
  std::vector<MultilaterationSample> s;
  for (int k = 0; k < 80; ++k) {
    const int a = k % 8, b = (k + 1) % 8;
    const Vec3 p_tag = tagPosition(p + Vec3(0, 0, 1.0), Quat::Identity(), kUtilTagOffset_b);
    MultilaterationSample m;
    m.z = {0.0025 * k, a, b, range(p_tag, anchors.find(b)->m) - range(p_tag, anchors.find(a)->m)};
    s.push_back(m);
  }
  // WHEN solving on the floor (z = 0.03) and freely
  const auto floor = multilaterateOnFloor(s, anchors, kUtilTagOffset_b, {Vec3(0, 0, 0.5)}, 0.03);
  const auto free = multilaterate(s, anchors, kUtilTagOffset_b, {Vec3(0, 0, 0.5)});
  // THEN the floor solve keeps z and its covariance has no z part; the free one follows the bias up
  ASSERT_TRUE(floor && free);
  EXPECT_DOUBLE_EQ(floor->w_p0.z(), 0.03);
  EXPECT_EQ(floor->covariance(2, 2), 0.0);
  EXPECT_LT((floor->w_p0.head<2>() - p.head<2>()).norm(), 0.5);
  EXPECT_GT(free->w_p0.z(), 0.8);
}

TEST(Multilateration, OnTheFloorGuessesThatDifferOnlyInHeightAreSolvedOnce) {
  // GIVEN noisy TDoA of a body on the floor, and the start-up's guesses: two share x and y, one does not
  const AnchorTable anchors = arenaAnchors();
  const Vec3 p(1.0, -1.5, 0.03);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<MultilaterationSample> s;
  for (int k = 0; k < 120; ++k) {
    const int a = k % 8, b = (k + 3) % 8;
    const Vec3 p_tag = tagPosition(p, Quat::Identity(), kUtilTagOffset_b);
    MultilaterationSample m;
    m.z = {0.0025 * k, a, b, range(p_tag, anchors.find(b)->m) - range(p_tag, anchors.find(a)->m) + noise(rng)};
    s.push_back(m);
  }
  const std::vector<Vec3> guesses = {Vec3(0.5, 0.0, 0.5), Vec3(0.5, 0.0, 1.5), Vec3(-2.0, 2.0, 1.0)};
  // WHEN solving with all three guesses, and with each guess alone (the reference: every start solved)
  const auto all = multilaterateOnFloor(s, anchors, kUtilTagOffset_b, guesses, 0.03);
  const auto g0 = multilaterateOnFloor(s, anchors, kUtilTagOffset_b, {guesses[0]}, 0.03);
  const auto g1 = multilaterateOnFloor(s, anchors, kUtilTagOffset_b, {guesses[1]}, 0.03);
  const auto g2 = multilaterateOnFloor(s, anchors, kUtilTagOffset_b, {guesses[2]}, 0.03);
  ASSERT_TRUE(all && g0 && g1 && g2);
  // THEN the guesses that differ only in height give the same solve, bit for bit (so one of them is skipped) …
  EXPECT_EQ(g0->w_p0, g1->w_p0);
  EXPECT_EQ(g0->rms_residual_m, g1->rms_residual_m);
  EXPECT_EQ(g0->covariance, g1->covariance);
  // … the multi-start result is one of the single-start solves, and it lies at the body's x and y
  EXPECT_TRUE(all->w_p0 == g0->w_p0 || all->w_p0 == g2->w_p0);
  EXPECT_LT((all->w_p0.head<2>() - p.head<2>()).norm(), 0.2);
}

}  // namespace
}  // namespace uwb
