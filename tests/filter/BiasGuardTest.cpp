/** @file BiasGuardTest.cpp
 *  @brief The bias guard (docs/math/filter.md F24): the robust predictive NLL, and the weight of the corrected filter
 *         following the evidence: towards the correction when it fits the flight, away from it when it does not.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "FilterTestUtil.h"
#include "uwb/filter/BiasGuard.h"
#include "uwb/filter/TdoaLocalizer.h"

namespace uwb {
namespace {

using filtertest::Truth;

TEST(PredictiveNll, GaussianInsideTheHuberScaleLinearOutside) {
  // GIVEN innovations at 2σ and at 5σ with S = 0.01 m²
  const double half_log_s = 0.5 * std::log(0.01);
  // THEN inside k = 3 the NLL is the Gaussian ½ u² + ½ log S, beyond it k u − ½ k² + ½ log S
  EXPECT_NEAR(predictiveNll(4.0, 0.01), 2.0 + half_log_s, 1e-12);
  EXPECT_NEAR(predictiveNll(25.0, 0.01), 3.0 * 5.0 - 4.5 + half_log_s, 1e-12);
  // AND the two branches meet at u = k
  EXPECT_NEAR(predictiveNll(9.0, 0.01), 4.5 + half_log_s, 1e-12);
  // AND a wider predictive density costs more for the same normalised innovation
  EXPECT_GT(predictiveNll(1.0, 0.04), predictiveNll(1.0, 0.01));
  // AND a non-positive variance has no density
  EXPECT_TRUE(std::isinf(predictiveNll(1.0, 0.0)));
}

/// A body hovering still at one point with per-pair TDoA offsets that do not look like a position shift
/// (+0.35 m on the pairs from anchor 1 and 5, −0.3 m on the pair from anchor 3).
double pairOffset(int id_a) {
  return id_a == 1 || id_a == 5 ? 0.35 : id_a == 3 ? -0.3 : 0.0;
}

struct HoverRun {
  double guarded_error_m, plain_error_m, corrected_error_m, weight;
};

const Vec3 kHoverPosition(0.5, -0.3, 1.5);

/// 20 s of a still hover at kHoverPosition with the pairOffset() errors on the TDoA.
SensorLog hoverLog(unsigned seed) {
  const auto truth = [](double) { return Truth{kHoverPosition, Vec3::Zero(), Vec3::Zero()}; };
  return filtertest::flightLog(filtertest::arenaAnchors(), truth, 0.0, 20.0, 0.1, true, seed,
                               [](double, int id_a) { return pairOffset(id_a); });
}

HoverRun hoverWith(const BiasPredictor& bias) {
  const SensorLog log = hoverLog(3);
  EkfParams params;
  params.ground_phase = GroundPhase::kNone;
  GuardedEstimator est(params, filtertest::arenaAnchors(), bias);
  SensorEventCursor events(log);
  for (SensorEvent ev; events.next(ev);) {
    if (ev.kind == SensorEvent::Kind::kImu) est.addImu(ev.t_s, log.imu[ev.index].imu);
    else if (ev.kind == SensorEvent::Kind::kTdoa) est.addTdoa(log.tdoa[ev.index]);
  }
  EXPECT_TRUE(est.ready());
  const Vec3& p = kHoverPosition;
  return {(est.estimate().x.w_p_b - p).norm(), (est.uncorrected().estimate().x.w_p_b - p).norm(),
          (est.corrected().estimate().x.w_p_b - p).norm(), est.weight()};
}

BiasPredictor offsetPredictor(double sign) {
  return [sign](const TdoaFeature& f) { return BiasPrediction{sign * pairOffset(f.id_a), 0.0, 1.0}; };
}

TEST(BiasGuard, FollowsACorrectionThatFitsTheFlight) {
  // GIVEN per-pair TDoA offsets and a bias model that knows them
  // WHEN the guarded estimator runs 20 s
  const HoverRun r = hoverWith(offsetPredictor(1.0));
  // THEN the correction is trusted, the corrected filter is better than the plain one, and the output is it
  EXPECT_GT(r.weight, 0.95);
  EXPECT_LT(r.corrected_error_m, r.plain_error_m);
  EXPECT_LT(r.guarded_error_m, r.corrected_error_m + 0.05 * r.plain_error_m + 0.01);
}

TEST(BiasGuard, LeavesACorrectionThatDoesNotFit) {
  // GIVEN the same offsets and a bias model with the wrong sign (it doubles the error)
  // WHEN the guarded estimator runs 20 s
  const HoverRun r = hoverWith(offsetPredictor(-1.0));
  // THEN the correction is dropped from the output, which is the plain filter's, better than the corrected one
  EXPECT_LT(r.weight, 0.05);
  EXPECT_GT(r.corrected_error_m, r.plain_error_m);
  EXPECT_LT(r.guarded_error_m, r.plain_error_m + 0.05 * r.corrected_error_m + 0.01);
}

TEST(BiasGuard, LocalizerUsesTheGuardOnlyWithABiasModelAndWhenOn) {
  // GIVEN a hovering flight with per-pair offsets and the wrong-sign bias model
  const AnchorTable anchors = filtertest::arenaAnchors();
  const Vec3& p = kHoverPosition;
  const SensorLog log = hoverLog(4);
  EkfParams on;
  on.ground_phase = GroundPhase::kNone;
  EXPECT_TRUE(on.bias_guard);  // on by default (F24)
  EkfParams off = on;
  off.bias_guard = false;
  // WHEN localizing without a model, with the model unguarded and guarded
  const LocalizerResult plain = TdoaLocalizer(on, anchors).run(log);
  const LocalizerResult unguarded = TdoaLocalizer(off, anchors, offsetPredictor(-1.0)).run(log);
  const LocalizerResult guarded = TdoaLocalizer(on, anchors, offsetPredictor(-1.0)).run(log);
  // THEN only the guarded run reports a weight, and its last output is the plain filter's to within millimetres
  EXPECT_TRUE(std::isnan(plain.summary.bias_guard_final_weight));
  EXPECT_TRUE(std::isnan(unguarded.summary.bias_guard_final_weight));
  EXPECT_LT(guarded.summary.bias_guard_final_weight, 0.05);
  EXPECT_LT(guarded.summary.bias_guard_mean_weight, 0.5);
  EXPECT_LT((guarded.estimates.back().x.w_p_b - plain.estimates.back().x.w_p_b).norm(), 0.01);
  EXPECT_GT((unguarded.estimates.back().x.w_p_b - p).norm(), (plain.estimates.back().x.w_p_b - p).norm());
}

TEST(BiasGuard, TdoaOnTheFloorAreNoEvidence) {
  // GIVEN a take-off log (on the floor with the motors running until 2 s, then a climb to a hover) whose floor TDoA
  // carry a height bias of +1 m, and a bias model that predicts an offset on two pairs everywhere
  filtertest::TakeoffLogSpec spec;
  spec.tdoa_dz = [](double t) { return t < 2.0 ? 1.0 : 0.0; };
  const SensorLog log = filtertest::takeoffLog(spec);
  GuardedEstimator est(EkfParams{}, filtertest::arenaAnchors(), offsetPredictor(1.0));
  // WHEN the events are fed
  double last_ground_log_odds = std::numeric_limits<double>::quiet_NaN();
  SensorEventCursor events(log);
  for (SensorEvent ev; events.next(ev);) {
    if (ev.kind == SensorEvent::Kind::kImu) est.addImu(ev.t_s, log.imu[ev.index].imu);
    else if (ev.kind == SensorEvent::Kind::kTdoa) est.addTdoa(log.tdoa[ev.index]);
    if (ev.t_s < 1.9) last_ground_log_odds = est.logOdds();
  }
  // THEN the comparison has not moved on the floor (F24: its TDoA carry the floor-level bias neither filter models),
  // and it has in flight
  EXPECT_EQ(last_ground_log_odds, 0.0);
  EXPECT_NE(est.logOdds(), 0.0);
}

TEST(BiasGuard, MixtureOfEqualFiltersIsEitherFilter) {
  // GIVEN a bias model that predicts no bias: both filters see the same measurements
  const HoverRun r = hoverWith([](const TdoaFeature&) { return BiasPrediction{0.0, 0.0, 1.0}; });
  // THEN the log-odds never move, and the mixture is the (identical) filters' estimate
  EXPECT_NEAR(r.weight, 0.5, 1e-12);
  EXPECT_NEAR(r.guarded_error_m, r.plain_error_m, 1e-12);
  EXPECT_NEAR(r.corrected_error_m, r.plain_error_m, 1e-12);
}

}  // namespace
}  // namespace uwb
