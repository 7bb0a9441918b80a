/** @file RunDiagnosticsTest.cpp
 *  @brief The checks after a run (eval/RunDiagnostics.h): each one names its fault on a short real flight and on a
 *         simulated one, and stays silent without the fault.
 */
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>

#include "support/TestSupport.h"
#include "uwb/eval/FaultInjection.h"
#include "uwb/eval/RunDiagnostics.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace uwb {
namespace {

/// One check at a time keeps each test to a few re-runs.
RunDiagnosticParams only(bool survey_fit, bool anchor_survey, bool clock_offset) {
  RunDiagnosticParams p;
  p.survey_fit = survey_fit;
  p.anchor_survey = anchor_survey;
  p.clock_offset = clock_offset;
  return p;
}

RunDiagnostics diagnose(const Flight& flight, const AnchorSurvey& survey, const RunDiagnosticParams& p) {
  const LocalizationOptions opt;
  const LocalizationRun run = localizeFlight(flight, survey, opt);
  return diagnoseRun(flight, survey, opt, run, {}, p);
}

FaultSpec fault(FaultKind kind, int anchor_id) { return {kind, 0.0, 1e9, anchor_id, 1}; }

/// 0425-traj2 (37 s), the flight of the figures.
struct RealFlight {
  Flight flight;
  AnchorSurvey survey;
};
std::optional<RealFlight> loadReal() {
  const auto path = test::pilotFlight("0425-traj2");
  if (!path) return std::nullopt;
  return RealFlight{readFlightCsv(path->string()), readAnchorSurvey(test::pilotSurvey("0425").string())};
}

TEST(EstimateResiduals, ZeroAtTheTruePoseAndAnchorJacobiansMatchFiniteDifferences) {
  AnchorSurvey survey = sim::paperAnchors();
  const Vec3 b_t(0.0, 0.0, 0.09);
  Trajectory traj(2);
  traj[0].t_s = 0.0, traj[1].t_s = 1.0;
  traj[0].w_p_b = traj[1].w_p_b = Vec3(0.3, -0.2, 1.4);
  const Vec3 tag = traj[0].w_p_b + b_t;
  const Vec3 a0 = survey.anchors[0].w_p, a1 = survey.anchors[1].w_p;
  const double z = (tag - a1).norm() - (tag - a0).norm();  // M1
  const std::vector<TdoaMeasurement> tdoa = {{0.5, survey.anchors[0].id, survey.anchors[1].id, z}};
  const auto res = estimateResiduals(tdoa, survey, traj, b_t, 0.0, 1.0, 2.0);
  ASSERT_EQ(res.size(), 1u);
  EXPECT_NEAR(res[0].r_m, 0.0, 1e-12);
  // r(a + δ) − r(a) ≈ −J δ (the residual is z − h)
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    AnchorSurvey moved = survey;
    moved.anchors[0].w_p[k] += h;
    const double dr = estimateResiduals(tdoa, moved, traj, b_t, 0.0, 1.0, 2.0)[0].r_m;
    EXPECT_NEAR(-dr / h, res[0].J_a[k], 1e-6);
    moved = survey;
    moved.anchors[1].w_p[k] += h;
    EXPECT_NEAR(-estimateResiduals(tdoa, moved, traj, b_t, 0.0, 1.0, 2.0)[0].r_m / h, res[0].J_b[k], 1e-6);
  }
  EXPECT_TRUE(estimateResiduals(tdoa, survey, traj, b_t, 0.6, 1.0, 2.0).empty());  // outside the window
  EXPECT_TRUE(estimateResiduals(tdoa, survey, traj, b_t, 0.0, 1.0, 0.5).empty());  // across a gap > max_gap_s
}

TEST(TruncatedRms, ClipsGrossResiduals) {
  std::vector<EstimateResidual> r(4);
  r[0].r_m = 0.3, r[1].r_m = -0.3, r[2].r_m = 0.3, r[3].r_m = 50.0;
  EXPECT_NEAR(truncatedRms(r, 1.0), std::sqrt((3 * 0.09 + 1.0) / 4.0), 1e-12);
  EXPECT_EQ(truncatedRms({}, 1.0), 0.0);
}

TEST(RunDiagnosticsReal, CleanFlightIsSilent) {
  const auto real = loadReal();
  UWB_REQUIRE_REAL_DATA(real);
  EXPECT_FALSE(RunDiagnosticParams{}.clock_offset);  // the lag search is opt-in: it does not work on real flights
  const RunDiagnostics d = diagnose(real->flight, real->survey, only(true, true, true));
  EXPECT_TRUE(d.warnings().empty()) << d.verdict();
  EXPECT_EQ(d.verdict(), "silent");
  EXPECT_TRUE(d.anchors.done);
  EXPECT_TRUE(d.clock.done);
  EXPECT_LT(d.survey.truncated_rms_m, RunDiagnosticParams{}.survey_fit_max_rms_m);
  EXPECT_EQ(d.anchors.named_id, -1);
  EXPECT_FALSE(d.clock.offset);
  EXPECT_GE(d.clock.lags_s.size(), 6u);  // the coarse grid and the two refinements around its best
}

// A log that starts in the air and ends on the floor (a user's log started mid-flight). Its first "take-off" is after
// the landing (the body leaving rest on the floor): a check that counted from there saw only floor-level residuals and
// reported the clean survey as one of another arena (0425-traj2 from 10 s: 0.91 m). And the residuals on the floor
// weigh the more the shorter the flight (0425-traj9 from 20 s: 6 s in the air, 0.50 m with them).
TEST(RunDiagnosticsReal, ALogThatStartsInTheAirAndLandsIsSilent) {
  const auto real = loadReal();
  UWB_REQUIRE_REAL_DATA(real);
  const LocalizationOptions opt;
  const AnchorSurvey& survey = real->survey;  // traj2 and traj9 are both of 0425
  for (const auto& [name, t0] : {std::pair<const char*, double>{"0425-traj2", 10.0}, {"0425-traj9", 20.0}}) {
    SCOPED_TRACE(name);
    const auto path = test::pilotFlight(name);
    ASSERT_TRUE(path);
    const Flight whole = readFlightCsv(path->string());
    const Flight cut = sliceFlight(whole, t0, whole.timeSpan().second);
    const LocalizationRun run = localizeFlight(cut, survey, opt);
    EXPECT_TRUE(run.summary.started_in_motion);
    ASSERT_FALSE(std::isnan(run.summary.landing_t_s));  // the rest at the end is a landing
    EXPECT_GT(run.summary.landing_t_s, run.summary.ready_t_s);
    ASSERT_FALSE(run.summary.ground_entered_t_s.empty());  // the ground periods are listed, the landing among them
    EXPECT_EQ(run.summary.ground_entered_t_s.back(), run.summary.landing_t_s);
    const RunDiagnostics d = diagnoseRun(cut, survey, opt, run, {}, only(true, false, false));
    EXPECT_FALSE(d.survey.misfit) << d.verdict();
    EXPECT_LT(d.survey.truncated_rms_m, 0.4);
    EXPECT_GT(d.survey.n, 1500u);  // the flight from the fix to the landing, not the floor after it
    // the whole flight from the ground does not start in motion; it enters the ground before it takes off
    const LocalizationRun from_ground = localizeFlight(whole, survey, opt);
    EXPECT_FALSE(from_ground.summary.started_in_motion);
    ASSERT_FALSE(from_ground.summary.ground_left_t_s.empty());
    EXPECT_LT(from_ground.summary.ground_entered_t_s.front(), from_ground.summary.takeoff_t_s);
    EXPECT_EQ(from_ground.summary.ground_left_t_s.front(), from_ground.summary.takeoff_t_s);
  }
}

TEST(RunDiagnosticsReal, NamesTheAnchorSurveyedOneMetreOff) {
  auto real = loadReal();
  UWB_REQUIRE_REAL_DATA(real);
  const int id = real->survey.anchors[0].id;  // the fault suite's anchor
  injectFault(fault(FaultKind::kAnchorSurveyOff, id), real->flight, real->survey);  // +1 m in x
  const RunDiagnostics d = diagnose(real->flight, real->survey, only(true, true, false));
  EXPECT_FALSE(d.survey.misfit);
  ASSERT_EQ(d.anchors.named_id, id) << d.verdict();
  EXPECT_NEAR(d.anchors.named_offset_m.x(), -1.0, 0.35);  // true − surveyed
  ASSERT_EQ(d.warnings().size(), 1u);
  EXPECT_NE(d.warnings()[0].find("anchor " + std::to_string(id)), std::string::npos);
  // the corrected survey brings the anchor closer to its true place than the 1 m of the fault (0.82 m left with the
  // defaults)
  const AnchorSurvey fixed = correctedSurvey(real->survey, d.anchors);
  EXPECT_LT((fixed.anchors[0].w_p - (real->survey.anchors[0].w_p - Vec3(1.0, 0.0, 0.0))).norm(), 0.9);
}

// The clock check does not find the 0.5 s offset on the real flights (docs/robustness.md: the residual power
// changes by < 10 %); on the simulated flight below it does.

TEST(RunDiagnosticsReal, SurveyOfAnotherArenaOrShiftedIsReported) {
  auto real = loadReal();
  UWB_REQUIRE_REAL_DATA(real);
  {
    Flight f = real->flight;
    AnchorSurvey s = real->survey;
    injectFault(fault(FaultKind::kSurveyOtherArena, 0), f, s);
    const RunDiagnostics d = diagnose(f, s, only(true, false, false));
    EXPECT_TRUE(d.survey.misfit) << d.survey.truncated_rms_m;
    ASSERT_FALSE(d.warnings().empty());
    // what the estimator itself saw (its innovations beyond chance, filter.md F30) comes before the survey is blamed
    const std::vector<std::string> w = d.warnings();
    const auto has = [](const char* text) { return [text](const std::string& x) { return x.find(text) != x.npos; }; };
    const auto fit = std::find_if(w.begin(), w.end(), has("does not fit"));
    ASSERT_NE(fit, w.end());
    const auto chance = std::find_if(w.begin(), w.end(), has("beyond chance"));
    if (chance != w.end()) {
      EXPECT_LT(chance - w.begin(), fit - w.begin());
    }
  }
  {
    Flight f = real->flight;
    AnchorSurvey s = real->survey;
    injectFault(fault(FaultKind::kSurveyShifted, 0), f, s);
    const RunDiagnostics d = diagnose(f, s, only(true, false, false));
    EXPECT_FALSE(d.survey.misfit);  // TDoA cannot see a translation …
    EXPECT_TRUE(d.survey.frame_offset);  // … the ground truth can
    EXPECT_NEAR(d.survey.mean_error_m.x(), 10.0, 1.0);
  }
}

// One TDoA in five off by ±5 m over the whole flight: the estimate holds (the gate rejects them), the other residuals
// fit the survey, so the warning names outliers in the measurements and does not blame the survey.
TEST(RunDiagnosticsReal, TdoaOutliersAreNamedAsSuchNotAsASurveyMisfit) {
  auto real = loadReal();
  UWB_REQUIRE_REAL_DATA(real);
  Flight f = real->flight;
  for (std::size_t k = 0; k < f.tdoa.size(); k += 5) f.tdoa[k].tdoa_m += (k % 10 == 0) ? 5.0 : -5.0;
  const RunDiagnostics d = diagnose(f, real->survey, only(true, false, false));
  EXPECT_GT(d.survey.gross_fraction, 0.15);
  EXPECT_GT(d.survey.truncated_rms_m, 0.45);  // the truncated RMS alone called this a misfit
  EXPECT_LT(d.survey.inlier_rms_m, 0.3);
  EXPECT_FALSE(d.survey.misfit) << d.verdict();
  EXPECT_TRUE(d.survey.outliers) << d.verdict();
  const std::vector<std::string> w = d.warnings();
  ASSERT_EQ(w.size(), 1u) << d.verdict();
  EXPECT_NE(w[0].find("outliers in the measurements"), std::string::npos) << w[0];
  EXPECT_EQ(w[0].find("does not fit"), std::string::npos) << w[0];
  // and the survey of another arena still spreads the residuals below 1 m too
  Flight g = real->flight;
  AnchorSurvey s = real->survey;
  injectFault(fault(FaultKind::kSurveyOtherArena, 0), g, s);
  const RunDiagnostics other = diagnose(g, s, only(true, false, false));
  EXPECT_GT(other.survey.inlier_rms_m, 0.35) << other.verdict();
  EXPECT_TRUE(other.survey.misfit);
  EXPECT_FALSE(other.survey.outliers);
}

/// A simulated circle over the paper's anchors: every check silent, then each fault named.
TEST(RunDiagnosticsSim, EachCheckOnASimulatedFlight) {
  const sim::SimResult simres = sim::simulateFlight(
      sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kCircle, 30.0), sim::SimParams{}, /*seed=*/5);
  const RunDiagnostics clean = diagnose(simres.flight, simres.survey, RunDiagnosticParams{});
  EXPECT_EQ(clean.verdict(), "silent");
  {
    Flight f = simres.flight;
    AnchorSurvey s = simres.survey;
    const int id = s.anchors[2].id;
    injectFault(fault(FaultKind::kAnchorSurveyOff, id), f, s);
    const RunDiagnostics d = diagnose(f, s, only(true, true, false));
    EXPECT_EQ(d.anchors.named_id, id) << d.verdict();
  }
  {
    Flight f = simres.flight;
    AnchorSurvey s = simres.survey;
    injectFault(fault(FaultKind::kClockOffsetTdoa, 0), f, s);
    const RunDiagnostics d = diagnose(f, s, only(true, false, true));
    EXPECT_TRUE(d.clock.offset) << d.verdict();
    EXPECT_GT(d.clock.best_lag_s, 0.25);  // the residual power is flat near its minimum: the lag is coarse
    EXPECT_LT(d.clock.best_lag_s, 1.0);
  }
  {
    Flight f = simres.flight;
    AnchorSurvey s = simres.survey;
    injectFault(fault(FaultKind::kSurveyOtherArena, 0), f, s);
    EXPECT_TRUE(diagnose(f, s, only(true, false, false)).survey.misfit);
  }
}

}  // namespace
}  // namespace uwb
