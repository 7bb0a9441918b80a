/** @file RealDataLocalizationTest.cpp
 *  @brief Change indication on real flights (STYLE §10): replays UTIL pilot flights through the default filter and
 *         checks the airborne RMSE stays under committed bounds. Skips when the data is absent.
 *
 *  Bounds = the value of scripts/localize_all.sh for the committed filter + margin; a change to the filter
 *  updates them deliberately. Reference (default params): 0425-traj2 0.211 m, 0426-traj11 0.260 m, median of the
 *  16 TDoA2 pilot flights 0.260 m (docs/results.md),
 *  const4-trial1-tdoa2-traj2 (TDoA-only) 0.169 m.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "support/TestSupport.h"
#include "uwb/eval/EstimateChecks.h"
#include "uwb/eval/FaultInjection.h"
#include "uwb/eval/Localization.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

LocalizationRun replay(const std::filesystem::path& flight, const std::filesystem::path& survey) {
  const AnchorSurvey s = readAnchorSurvey(survey.string());
  const Flight f = readFlightCsv(flight.string());
  return localizeFlight(f, s);
}

/// replay() of a util-pilot flight with its session's survey; nullopt when the real data is absent.
std::optional<LocalizationRun> replayPilot(const std::string& name) {
  const auto flight = test::pilotFlight(name);
  if (!flight) return std::nullopt;
  return replay(*flight, test::pilotSurvey(name.substr(0, 4)));
}

TEST(RealDataLocalization, Pilot0425Traj2AirborneRmseUnderBound) {
  // GIVEN a real circle flight with ground phase and the 0425 accelerometer offset
  // WHEN localizing with the defaults (no ground-truth start)
  const std::optional<LocalizationRun> run = replayPilot("0425-traj2");
  UWB_REQUIRE_REAL_DATA(run);
  // THEN the airborne RMSE stays under the committed bound and nothing diverged
  ASSERT_TRUE(run->metrics);
  EXPECT_LT(run->metrics->airborne.rmse_m, 0.23);
  EXPECT_LT(run->metrics->whole.rmse_m, 0.28);
  EXPECT_LT(run->metrics->airborne.p99_m, 1.0);
  EXPECT_GT(run->summary.n_tdoa_used, 10000u);
  EXPECT_FALSE(std::isnan(run->summary.takeoff_t_s));
}

TEST(RealDataLocalization, GarbageTdoaMidFlightAreCaughtAndCostLittle) {
  // GIVEN a flight of the session the fault handling was not chosen on, with 5 s of uniformly random TDoA mid-flight
  // (docs/math/filter.md F16d, F16e; without them: airborne RMSE 4.2 m, the estimate walked off)
  const auto flight = test::pilotFlight("0426-traj11");
  UWB_REQUIRE_REAL_DATA(flight);
  const AnchorSurvey survey = readAnchorSurvey(test::pilotSurvey("0426").string());
  Flight f = readFlightCsv(flight->string());
  const LocalizationRun clean = localizeFlight(f, survey);
  ASSERT_TRUE(clean.metrics);
  AnchorSurvey s = survey;
  const FaultSpec garbage{FaultKind::kGarbageTdoa, 25.9, 30.9, 0, 2};
  injectFault(garbage, f, s);
  // WHEN localizing with the defaults
  const LocalizationRun run = localizeFlight(f, s);
  // THEN the rejection rate starts a re-acquisition within 0.6 s of the burst, and the flight's airborne RMSE stays
  // within 4× the clean one (0.78 against 0.24 m; no position information for 5 s while it circles at 1–2 m/s)
  ASSERT_TRUE(run.metrics);
  EXPECT_GE(run.summary.n_rejection_faults, 1u);
  ASSERT_FALSE(run.summary.reacquisition_t_s.empty());
  EXPECT_GT(run.summary.reacquisition_t_s.front(), garbage.t0_s);
  EXPECT_LT(run.summary.reacquisition_t_s.front(), garbage.t0_s + 0.6);
  EXPECT_LT(run.metrics->airborne.rmse_m, 4.0 * clean.metrics->airborne.rmse_m);
  // and 3 s after the burst the error is that of the clean flight again
  for (const PositionErrorSample& e : run.metrics->samples) {
    if (e.airborne && e.t_s > garbage.t1_s + 3.0 && e.t_s < garbage.t1_s + 6.0) {
      EXPECT_LT(e.error_norm_m, 0.6) << e.t_s;
    }
  }
}

TEST(RealDataLocalization, Pilot0425LandingDetectedAndPositionHeld) {
  // GIVEN the 0425 flights whose touchdown has no strong vibration burst at first (the estimate used to run away
  // upwards after ground contact: whole-flight RMSE 0.94, 0.53, 0.75 m)
  for (const char* name : {"0425-traj1", "0425-traj5", "0425-traj7"}) {
    // WHEN localizing with the defaults
    const std::optional<LocalizationRun> run = replayPilot(name);
    UWB_REQUIRE_REAL_DATA(run);
    // THEN the landing is detected after the take-off and the whole-flight RMSE stays near the airborne one
    ASSERT_TRUE(run->metrics) << name;
    EXPECT_FALSE(std::isnan(run->summary.landing_t_s)) << name;
    EXPECT_GT(run->summary.landing_t_s, run->summary.takeoff_t_s) << name;
    EXPECT_LT(run->metrics->whole.rmse_m, 0.45) << name;
    EXPECT_LT(run->metrics->airborne.rmse_m, 0.40) << name;
  }
}

TEST(RealDataLocalization, ATouchdownIsNotReadAsATakeOff) {
  // GIVEN flights whose touchdowns stop a descent hard (the floor's deceleration integrated from zero read as a climb
  // 0.2 s after the landing of 0425-traj12 once shaking no longer vetoed the climb; 0426-traj12 left the ground twice
  // after its landing, a false "position lost")
  for (const char* name : {"0425-traj12", "0426-traj12"}) {
    // WHEN localizing with the defaults
    const std::optional<LocalizationRun> run = replayPilot(name);
    UWB_REQUIRE_REAL_DATA(run);
    // THEN the ground is not left within 1 s of any entry after the take-off (filter.md F15: the detector starts from
    // the descent the floor stops); the last 0.5 s of the log are not judged (the motors stop there, and between the
    // end of their shaking and the rest test's hold the mode may leave the floor for 0.1 s, docs/robustness.md)
    const LocalizerSummary& s = run->summary;
    for (double entered : s.ground_entered_t_s) {
      if (!(entered > s.takeoff_t_s)) continue;
      for (double left : s.ground_left_t_s) {
        if (left > s.end_t_s - 0.5) continue;
        EXPECT_FALSE(left > entered && left < entered + 1.0) << name << ": entered " << entered << ", left " << left;
      }
    }
  }
}

TEST(RealDataLocalization, TdoaThatScatterOnTheFloorAfterALandingDoNotLiftTheEstimate) {
  // GIVEN 0425-traj12 without its downward range (a user without the Flow deck): a rough landing (the body bounces for
  // 0.8 s, gyro up to 1.4 rad/s) on a spot whose floor-level TDoA scatter by 2 m, and the log ends 1.7 s later
  const auto flight = test::pilotFlight("0425-traj12");
  UWB_REQUIRE_REAL_DATA(flight);
  const Flight f = readFlightCsv(flight->string());
  const AnchorSurvey survey = readAnchorSurvey(test::pilotSurvey("0425").string());
  LocalizationOptions opt;
  opt.params.fuse_tof = false;
  // WHEN localizing
  const LocalizationRun run = localizeFlight(f, survey, opt);
  ASSERT_TRUE(run.metrics);
  EstimateCheckParams cp;
  cp.floor_z_m = opt.params.ground_z_m;
  const EstimateChecks c = checkEstimate(run.trajectory, *run.metrics, cp);
  // THEN the TDoA window that overruled the floor after the landing, too scattered to locate the tag within the flight
  // range, does not set its height (filter.md F29c; it set 1.3 m with a σ of 2 m, and the gate-free acquisition's
  // floor TDoA took the estimate to 6.3 m, above every anchor): the estimate on the floor after flying stays below
  // 1.2 m (the mode's flip at the motors' stop, docs/robustness.md, still lifts it at the log's end) and the flight is
  // unchanged
  EXPECT_LT(c.max_z_on_ground_m, 1.2);
  EXPECT_LT(run.metrics->whole.max_m, 1.5);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.26);
}

TEST(RealDataLocalization, WithTheDownwardRangeTheHeightBandIsTheFiltersOwn) {
  // GIVEN a flight whose log carries the Flow deck's range (fused by default, F21): the height error is about 1 cm
  const std::optional<LocalizationRun> run = replayPilot("0425-traj2");
  UWB_REQUIRE_REAL_DATA(run);
  ASSERT_TRUE(run->metrics);
  ASSERT_GT(run->summary.n_tof_used, 500u);
  // WHEN the reported σ is compared with the error
  EstimateCheckParams cp;
  cp.floor_z_m = EkfParams{}.ground_z_m;
  const EstimateChecks c = checkEstimate(run->trajectory, *run->metrics, cp);
  // THEN the height band means what it says (filter.md F23e: the TDoA bias adds nothing to the height the ToF holds;
  // before, 1σ and 2σ covered 100 % of the z errors, the band ±0.2–0.3 m about a 1 cm error)
  EXPECT_GT(c.coverage_1sigma.z(), 0.5);
  EXPECT_LT(c.coverage_1sigma.z(), 0.95);
  EXPECT_GT(c.coverage_2sigma.z(), 0.85);
}

TEST(RealDataLocalization, Pilot0426Traj11WithObstaclesUnderBound) {
  // GIVEN an obstacle (NLOS) flight
  // WHEN localizing with the defaults
  const std::optional<LocalizationRun> run = replayPilot("0426-traj11");
  UWB_REQUIRE_REAL_DATA(run);
  // THEN
  ASSERT_TRUE(run->metrics);
  EXPECT_LT(run->metrics->airborne.rmse_m, 0.29);
}

TEST(RealDataLocalization, PilotTdoa2MedianAirborneRmseUnderBound) {
  // GIVEN all 16 TDoA2 pilot flights (0425-traj1…12, 0426-traj1/2/11/12)
  std::vector<std::pair<std::string, std::string>> flights;
  for (int i = 1; i <= 12; ++i) flights.emplace_back("0425-traj" + std::to_string(i), "0425");
  for (int i : {1, 2, 11, 12}) flights.emplace_back("0426-traj" + std::to_string(i), "0426");
  std::vector<double> rmse;
  for (const auto& [name, day] : flights) {
    // WHEN localizing each with the defaults
    const std::optional<LocalizationRun> run = replayPilot(name);
    UWB_REQUIRE_REAL_DATA(run);
    ASSERT_TRUE(run->metrics) << name;
    EXPECT_LT(run->metrics->airborne.rmse_m, 0.40) << name;
    rmse.push_back(run->metrics->airborne.rmse_m);
  }
  // THEN the median airborne RMSE stays under the committed bound (0.260 m with the defaults)
  std::sort(rmse.begin(), rmse.end());
  EXPECT_LT(0.5 * (rmse[7] + rmse[8]), 0.275);
}

TEST(RealDataLocalization, FinalExtractTdoaOnlyUnderBound) {
  // GIVEN a released UTIL flight without IMU
  const std::filesystem::path dir = test::dataDir() / "real" / "util-final-extract";
  const std::filesystem::path flight = dir / "const4-trial1-tdoa2-traj2.csv";
  if (!std::filesystem::exists(flight)) GTEST_SKIP() << "real flight data not found under " << dir;
  // WHEN localizing (the TDoA-only model is selected automatically)
  const LocalizationRun run = replay(flight, dir / "survey" / "anchor_const4_survey.txt");
  // THEN
  ASSERT_TRUE(run.metrics);
  EXPECT_EQ(run.summary.process_model, ProcessModel::kConstantVelocity);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.20);
}

}  // namespace
}  // namespace uwb
