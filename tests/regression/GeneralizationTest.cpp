/** @file GeneralizationTest.cpp
 *  @brief Flights the defaults were not chosen on (docs/math/filter.md F14–F23, `uwbtdoa protocol`): a real flight
 *         whose log starts in the air, a simulated start in hover, a hand-carried start, a simulated flight with two
 *         take-offs, a simulated landing (F26), TDoA3 (random pairs) real and simulated. Bounds are
 *         the protocol's values at the time of commit plus a margin.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <utility>

#include "support/TestSupport.h"
#include "uwb/eval/EstimateChecks.h"
#include "uwb/eval/Localization.h"
#include "uwb/eval/ProtocolScenarios.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace uwb {
namespace {

EstimateChecks checks(const LocalizationRun& run, const Flight& flight, const AnchorSurvey& survey) {
  EstimateCheckParams cp;
  cp.ceiling_z_m = -1e300;
  for (const Anchor& a : survey.anchors) cp.ceiling_z_m = std::max(cp.ceiling_z_m, a.w_p.z());
  cp.t_start_s = flight.tdoa.front().t_s;
  return checkEstimate(run.trajectory, *run.metrics, cp);
}

const SimScenarioRun& scenario(const std::vector<SimScenarioRun>& runs, const std::string& name) {
  for (const SimScenarioRun& r : runs)
    if (r.name == name) return r;
  throw std::runtime_error("no scenario " + name);
}

/// A util-pilot flight and the survey of its session.
struct PilotFlight {
  Flight flight;
  AnchorSurvey survey;
};

/// The util-pilot flight `name` (e.g. "0425-traj3") and its session's survey; nullopt when the real data is absent.
std::optional<PilotFlight> readPilotFlight(const std::string& name) {
  const auto path = test::pilotFlight(name);
  if (!path) return std::nullopt;
  return PilotFlight{readFlightCsv(path->string()), readAnchorSurvey(test::pilotSurvey(name.substr(0, 4)).string())};
}

/// The run was scored against the truth, its airborne RMSE below `rmse_m` and its largest airborne error below `max_m`.
void expectAirborneErrorBelow(const LocalizationRun& run, double rmse_m, double max_m) {
  ASSERT_TRUE(run.metrics);
  EXPECT_LT(run.metrics->airborne.rmse_m, rmse_m);
  EXPECT_LT(run.metrics->airborne.max_m, max_m);
}

/// The TDoA the run used, rejected or spent on its start (of n_tdoa_total).
double tdoaAccountedFor(const LocalizerSummary& sum) {
  return static_cast<double>(sum.n_tdoa_used + sum.n_tdoa_rejected + sum.n_tdoa_start);
}

/// A log started in the air: the run is scored, its position found within 1 s of the first TDoA, its airborne RMSE
/// below 0.30 m and below 0.40 m 3–5 s after the start; its checks in `c`.
void expectFoundAtOnce(const LocalizationRun& run, const SimScenarioRun& s, EstimateChecks* c) {
  ASSERT_TRUE(run.metrics);
  EXPECT_LT(run.summary.ready_t_s - s.flight.tdoa.front().t_s, 1.0);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.30);
  *c = checks(run, s.flight, s.survey);
  EXPECT_LT(c->rmse_3_to_5s_m, 0.40);
}

/// A 40 s simulated flight of the given shape at the paper's anchors, its sensors the simulator's defaults as
/// `sensors` changes them, localized with the defaults.
LocalizationRun localizeSimulated(sim::TrajectoryShape shape, std::uint64_t seed,
                                  const std::function<void(sim::SimParams&)>& sensors) {
  sim::SimParams sp;
  sensors(sp);
  const sim::SimResult s = sim::simulateFlight(sim::makeScenario(sim::paperAnchors(), shape, 40.0), sp, seed);
  return localizeFlight(s.flight, s.survey);
}

TEST(Generalization, RealFlightLoggedFromMidAir) {
  // GIVEN a real dev flight cut to start 10 s after power-up (in the air) and to end 1 s before the landing
  const std::optional<PilotFlight> pilot = readPilotFlight("0425-traj3");
  UWB_REQUIRE_REAL_DATA(pilot);
  const AnchorSurvey& survey = pilot->survey;
  const Flight cut = sliceFlight(pilot->flight, 10.0, 29.5);
  // WHEN localizing it with the defaults
  const LocalizationRun run = localizeFlight(cut, survey);
  // THEN the airborne RMSE is that of a whole flight, 3–5 s after the first TDoA the error is small, no step jumps
  ASSERT_TRUE(run.metrics);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.30);
  const EstimateChecks c = checks(run, cut, survey);
  EXPECT_LT(c.rmse_3_to_5s_m, 0.35);
  EXPECT_LT(c.max_airborne_step_m, 0.3);
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
}

TEST(Generalization, RealLogBegunDuringAShakingBurstInFlightIsNotPutOnTheFloor) {
  // GIVEN real dev flights cut to start in the air where the IMU shakes as on the floor with the motors running
  // (F18 contact: 0426-traj12 at 2 m from 13.70 s for 0.47 s, 0425-traj2 at 1.5 m from 9.13 s for 0.04 s)
  const struct {
    const char* flight;
    double t0_s, t1_s;
  } cuts[] = {{"0426-traj12", 13.56, 30.04}, {"0425-traj2", 8.46, 24.98}};
  for (const auto& k : cuts) {
    SCOPED_TRACE(k.flight);
    const std::optional<PilotFlight> pilot = readPilotFlight(k.flight);
    UWB_REQUIRE_REAL_DATA(pilot);
    // WHEN localizing with the defaults
    const LocalizationRun run = localizeFlight(sliceFlight(pilot->flight, k.t0_s, k.t1_s), pilot->survey);
    // THEN the first fix refutes the ground evidence (F16j): the estimate is never on the floor (before: 2.1 and
    // 1.5 m off for a second, airborne RMSE 0.49 and 0.39 m), and no take-off is reported
    ASSERT_TRUE(run.metrics);
    // (the flight-mode supervisor, filter.md F29, may not enter the floor at all for a burst this short)
    EXPECT_TRUE(run.summary.start_floor_refuted || run.summary.ground_entered_t_s.empty());
    EXPECT_TRUE(std::isnan(run.summary.takeoff_t_s));
    EXPECT_LT(run.metrics->airborne.max_m, 0.8);
    EXPECT_LT(run.metrics->airborne.rmse_m, 0.35);
  }
}

TEST(Generalization, RealLogBegunInAPlaceOfBiasedTdoaDoesNotRunAway) {
  // GIVEN a real dev flight logged from 29.45 s, in the air at a place whose TDoA are off by about 1 m
  const std::optional<PilotFlight> pilot = readPilotFlight("0426-traj11");
  UWB_REQUIRE_REAL_DATA(pilot);
  // WHEN localizing it with the defaults
  const LocalizationRun run = localizeFlight(sliceFlight(pilot->flight, 29.45, 48.59), pilot->survey);
  // THEN the acquisition after the replayed start (F16g′) does not carry the estimate away: before, its second second
  // of gate-free updates turned the roll, the estimate ran 8.6 m off and was re-acquired (airborne RMSE 1.72 m)
  ASSERT_TRUE(run.metrics);
  EXPECT_TRUE(run.summary.start_replayed);
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
  EXPECT_LT(run.metrics->airborne.max_m, 0.8);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.32);
}

TEST(Generalization, RealStartOnTheFloorSeesTheFloorLevelAnchorsLate) {
  // GIVEN a real flight of the other session whose first 1 s on the floor carries the floor-level delays (0426-traj1:
  // the pairs with one anchor at 0.2 m and one at 3 m are off by 3 m)
  const std::optional<PilotFlight> pilot = readPilotFlight("0426-traj1");
  UWB_REQUIRE_REAL_DATA(pilot);
  const auto& [flight, survey] = *pilot;
  // WHEN localizing with the defaults, and with the floor-level delays not modelled (F16f off)
  const LocalizationRun run = localizeFlight(flight, survey);
  LocalizationOptions off;
  off.params.floor_anchor_height_m = 0.0;
  const LocalizationRun run_off = localizeFlight(flight, survey, off);
  // THEN the estimate on the floor before the take-off is within 0.7 m of the body (the plain start: 2.4 m), and
  // the flight is unchanged
  ASSERT_TRUE(run.metrics && run_off.metrics);
  const EstimateChecks c = checks(run, flight, survey), c_off = checks(run_off, flight, survey);
  EXPECT_LT(c.max_error_before_takeoff_m, 0.7);
  EXPECT_GT(c_off.max_error_before_takeoff_m, 2.0);
  EXPECT_FALSE(run.summary.start_floor_refuted);  // F16j: the floor-biased free solve lies above the room
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.26);
}

TEST(Generalization, SimulatedLiftOffFromRestKeepsTheFloorLevelDelaysUntilTheBodyHasRisen) {
  // GIVEN simulated flights from the ground whose rotors spin up without floor shaking (the simulated IMU: rest, then
  // flight vibration) while the floor-level anchors are seen 2–3.6 m late (S18); three drones and rooms (seeds)
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {11, 12, 13}, "fast-paper");
  LocalizationOptions off;
  off.params.floor_anchor_height_m = 0.0;
  double sum_ratio = 0.0;
  for (const char* name : {"fast-paper-s11", "fast-paper-s12", "fast-paper-s13"}) {
    SCOPED_TRACE(name);
    const SimScenarioRun& s = scenario(runs, name);
    // WHEN localizing with the defaults, and with the floor-level delays not modelled (F16f off)
    const LocalizationRun run = localizeFlight(s.flight, s.survey);
    const LocalizationRun run_off = localizeFlight(s.flight, s.survey, off);
    // THEN on the floor and through the lift-off the estimate stays within 0.6 m of the body (without: 1.4–2.4 m)
    ASSERT_TRUE(run.metrics && run_off.metrics);
    const EstimateChecks c = checks(run, s.flight, s.survey), c_off = checks(run_off, s.flight, s.survey);
    EXPECT_LT(c.max_error_before_takeoff_m, 0.6);
    EXPECT_GT(c_off.max_error_before_takeoff_m, 1.2);
    // and no flight is more than 5 % worse airborne (s11 0.162 against 0.156 m, s12 and s13 the same or better)
    const double ratio = run.metrics->airborne.rmse_m / run_off.metrics->airborne.rmse_m;
    EXPECT_LT(ratio, 1.05);
    sum_ratio += ratio;
  }
  // AND over the three the airborne error is no worse (within 1 %)
  EXPECT_LT(sum_ratio / 3.0, 1.01);
}

TEST(Generalization, SimulatedStartInHover) {
  // GIVEN a simulated circle flight whose log starts 2 s after the climb (paper anchors, drone/room seed 11)
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {11}, "hover-start-paper");
  const SimScenarioRun& s = scenario(runs, "hover-start-paper-s11");
  // WHEN localizing
  const LocalizationRun run = localizeFlight(s.flight, s.survey);
  // THEN the position is found at once and the error is that of the rest of the flight within 3 s
  EstimateChecks c;
  ASSERT_NO_FATAL_FAILURE(expectFoundAtOnce(run, s, &c));
  EXPECT_GE(tdoaAccountedFor(run.summary), 0.9 * run.summary.n_tdoa_total);
}

TEST(Generalization, StartInTheAirAddsLittleToTheSameFlightFromTheGround) {
  // GIVEN the worst simulated start in hover of the protocol (paper anchors, seed 12: the room's bias is large
  // right after the log starts) and the same flight logged from the ground
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {12}, "hover-start-paper");
  const SimScenarioRun& s = scenario(runs, "hover-start-paper-s12");
  ASSERT_TRUE(s.cut);
  ASSERT_FALSE(s.whole.pose.empty());
  EXPECT_LT(s.whole.pose.front().w_p_b.z(), 0.1);
  EXPECT_LT(s.whole.tdoa.front().t_s, s.flight.tdoa.front().t_s);
  // WHEN localizing both
  const LocalizationRun cut = localizeFlight(s.flight, s.survey);
  const LocalizationRun whole = localizeFlight(s.whole, s.survey);
  ASSERT_TRUE(cut.metrics && whole.metrics);
  // THEN 3–5 s after the log starts the air start is within 0.1 m RMS of the flight that started on the ground
  // (the protocol: 0.451 against 0.378 m), and over the whole window within 10 % (0.290 against 0.272 m; without the
  // range-bias states of F27 0.314 against 0.302 m: they gain more on the flight that starts on the ground)
  const double ts = s.flight.tdoa.front().t_s;
  const double early_cut = airborneRmseInWindow(*cut.metrics, ts + 3.0, ts + 5.0);
  const double early_whole = airborneRmseInWindow(*whole.metrics, ts + 3.0, ts + 5.0);
  EXPECT_LT(early_cut, early_whole + 0.1);
  const auto [t0, t1] = s.flight.timeSpan();
  const double cut_rmse = airborneRmseInWindow(*cut.metrics, t0, t1);
  EXPECT_LT(cut_rmse, 1.10 * airborneRmseInWindow(*whole.metrics, t0, t1));
  EXPECT_LT(cut_rmse, 0.30);
}

TEST(Generalization, SimulatedHandCarriedStartWhileWalking) {
  // GIVEN a simulated flight carried by a walking person (1 m/s, turning, 2 Hz gait bob), logged from mid-walk
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {12}, "hand-carried-paper");
  const SimScenarioRun& s = scenario(runs, "hand-carried-paper-s12");
  ASSERT_TRUE(s.cut);
  // WHEN localizing
  const LocalizationRun run = localizeFlight(s.flight, s.survey);
  // THEN it is found within a second, tracked like a flight, nothing is read as on the ground, no output jumps
  EstimateChecks c;
  ASSERT_NO_FATAL_FAILURE(expectFoundAtOnce(run, s, &c));
  EXPECT_LT(c.max_airborne_step_m, 0.2);
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
  EXPECT_GE(tdoaAccountedFor(run.summary), 0.95 * run.summary.n_tdoa_total);
}

TEST(Generalization, SimulatedTwoTakeoffs) {
  // GIVEN a simulated circle flight, a landing, and a second flight (a hover) from where it landed
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {11}, "two-takeoffs-paper");
  const SimScenarioRun& s = scenario(runs, "two-takeoffs-paper-s11");
  // WHEN localizing
  const LocalizationRun run = localizeFlight(s.flight, s.survey);
  // THEN both flights are tracked, the body rested twice, nothing is below the floor or above the anchors on the
  // ground, and no output jumps while airborne
  ASSERT_TRUE(run.metrics);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.32);
  EXPECT_GE(run.summary.n_rest_periods, 2u);
  const EstimateChecks c = checks(run, s.flight, s.survey);
  EXPECT_FALSE(c.floor_or_ceiling_violated);
  EXPECT_LT(c.max_airborne_step_m, 0.3);
  EXPECT_GE(tdoaAccountedFor(run.summary), 0.9 * run.summary.n_tdoa_total);
}

TEST(Generalization, SimulatedLandingsAreNotPulledAwayByTheFloorLevelAnchors) {
  // GIVEN the simulated two-take-off flights (paper anchors, drone/room seeds 11 and 13): each of their landings
  // brings the tag within the floor-level anchors' delays (S18, metres) some 0.8 s before the IMU shows the rest
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {11, 13}, "two-takeoffs-paper");
  for (const char* name : {"two-takeoffs-paper-s11", "two-takeoffs-paper-s13"}) {
    SCOPED_TRACE(name);
    const SimScenarioRun& s = scenario(runs, name);
    // WHEN localizing with the defaults
    const LocalizationRun run = localizeFlight(s.flight, s.survey);
    // THEN near the floor after a descent each TDoA is taken with the floor's delay or without it, whichever it lies
    // nearer to (F16h): the largest error over the whole flight, landings included, stays below 0.8 m (0.64 and
    // 0.52 m; with the landing's TDoA taken as flight TDoA until the rest: 1.47 and 2.02 m), the airborne RMSE as before
    ASSERT_TRUE(run.metrics);
    EXPECT_LT(run.metrics->whole.max_m, 0.8);
    EXPECT_LT(run.metrics->airborne.rmse_m, 0.2);
    EXPECT_EQ(run.summary.n_landing_fixes, 0u);  // the start on the floor found the delays (F16i is not needed)
  }
}

TEST(Generalization, SimulatedTouchdownDoesNotSlideAway) {
  // GIVEN a simulated 30 s circle over UTIL constellation 4 (drone/room seed 718499, yaw rate 0.2 rad/s, IMU at
  // 500 Hz; `scripts/sim_sweep.py --seed 4242`): between its touchdown and the rest the IMU shows, the floor-level
  // anchors' TDoA pull on a body that sits still
  if (!std::filesystem::exists(test::dataDir() / "real" / "util-final-extract" / "survey" / "anchor_const4_survey.txt"))
    GTEST_SKIP() << "the util-const4 survey was not found under " << test::dataDir();
  sim::Scenario sc = sim::makeScenario(sim::anchorPreset("util-const4", test::dataDir().string()),
                                       sim::TrajectoryShape::kCircle, 30.0);
  sc.trajectory.yaw_rate_rps = 0.2;
  sc.trajectory.yaw_mode = sim::YawMode::kConstantRate;
  sim::SimParams sp;
  sp.imu.rate_hz = 500.0;
  const sim::SimResult s = sim::simulateFlight(sc, sp, 718499);
  // WHEN localizing with the defaults, and with the lateral acceleration noise of before F3a
  const LocalizationRun run = localizeFlight(s.flight, s.survey);
  LocalizationOptions loose;
  loose.params.lateral_acc_noise_mps2_sqrthz = 1.0;
  const LocalizationRun run_loose = localizeFlight(s.flight, s.survey, loose);
  // THEN the tilted thrust, level on the floor, holds the horizontal velocity: the largest error over the whole flight
  // stays below 0.8 m (0.57 m). With 1.0 the TDoA drove the still body to 3 m/s sideways (2.95 m off, σ 0.15 m) as
  // long as the simulator's gyro turn-on bias tilted the estimate; since the bias is read at rest and the tilt axes
  // learn theirs (filter.md F18z, F1) 1.0 holds it too (0.57 m): F3a is no longer the only guard
  ASSERT_TRUE(run.metrics && run_loose.metrics);
  EXPECT_LT(run.metrics->whole.max_m, 0.8);
  EXPECT_LT(run_loose.metrics->whole.max_m, 0.8);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.3);
}

TEST(Generalization, SimulatedStillHoverAfterAnOvershootIsNoLanding) {
  // GIVEN a simulated 20 s hover at 2.2 m after a 1.5 s take-off (paper anchors, drone/room seed 274872, IMU at
  // 100 Hz, at which a still hover reads as quiet as rest; `scripts/sim_sweep.py --extreme --seed 4343`): the
  // estimate overshoots the climb and dips back, a descent within 3 s of heights below 0.8 m, but those were the climb
  sim::Scenario sc = sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kHover, 20.0);
  sc.trajectory.yaw_rate_rps = 0.0;
  sc.trajectory.yaw_mode = sim::YawMode::kConstant;
  sc.trajectory.takeoff_s = 1.5;
  sc.trajectory.height_m = 2.2;
  sim::SimParams sp;
  sp.imu.rate_hz = 100.0;
  const sim::SimResult s = sim::simulateFlight(sc, sp, 274872);
  // WHEN localizing with the defaults
  const LocalizationRun run = localizeFlight(s.flight, s.survey);
  // THEN rest enters the ground only with heights reached at the descent (F18): on the floor before the take-off and
  // after the landing only (before: on the ground at 7.9 s, 2.2 m up, 1.9 m off for 1.5 s, airborne RMSE 0.78 m)
  ASSERT_TRUE(run.metrics);
  EXPECT_EQ(run.summary.ground_entered_t_s.size(), 2u);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.25);
  EXPECT_LT(run.metrics->airborne.max_m, 0.8);
}

TEST(Generalization, SimulatedLogBegunInTheAirLearnsTheFloorAtItsLanding) {
  // GIVEN a simulated zigzag (paper anchors, seed 9) logged from 12 s, in the air, to its end on the floor: the log
  // never saw the floor before, so it knows no floor-level delays, and the landing's TDoA carry them (S18, metres)
  const sim::SimResult s = sim::simulateFlight(sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kZigzag, 40.0),
                                               sim::SimParams{}, 9);
  const Flight cut = sliceFlight(s.flight, 12.0, s.flight.timeSpan().second);
  // WHEN localizing it with the defaults
  const LocalizationRun run = localizeFlight(cut, s.survey);
  // THEN at the rest after the landing the floor's delays and position are solved as at a start on the floor and fused
  // (F16i): the whole log's RMSE stays near the airborne one (0.40 m whole, 1.8 m largest error; without F16i the
  // position on the floor stayed where the touchdown's TDoA had pulled it: 0.87 m whole, 2.5 m largest)
  ASSERT_TRUE(run.metrics);
  EXPECT_EQ(run.summary.n_landing_fixes, 1u);
  EXPECT_LT(run.metrics->whole.rmse_m, 0.55);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.3);
}

TEST(Generalization, SimulatedImuLoggedAt100HzWithAStillHover) {
  // GIVEN a simulated zigzag whose IMU is logged at 100 Hz and TDoA at 100 Hz (a radio or uSD log): its still hover
  // before the landing reads as quiet as the motors off
  // WHEN localizing with the defaults
  const LocalizationRun run = localizeSimulated(sim::TrajectoryShape::kZigzag, 5, [](sim::SimParams& sp) {
    sp.imu.rate_hz = 100.0;
    sp.tdoa.rate_hz = 100.0;
  });
  // THEN the hover is not taken for the ground (at 2 m the floor height pulled the estimate 2 m down: airborne RMSE
  // 0.37 m, largest error 2.0 m), and the flight is as accurate as at 1 kHz (0.23 m)
  ASSERT_NO_FATAL_FAILURE(expectAirborneErrorBelow(run, 0.27, 0.8));
  EXPECT_EQ(run.summary.n_rest_periods, 2u);
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
}

TEST(Generalization, RealTdoa3FlightAndItsReportedSigma) {
  // GIVEN the util-pilot TDoA3 flight (random anchor pairs at about 200 Hz, the LPS mode of current firmware; no
  // default was chosen on it): the same eight anchors as the TDoA2 flights of its session, seen through up to 28 pairs
  const std::optional<PilotFlight> pilot = readPilotFlight("0425-traj13");
  UWB_REQUIRE_REAL_DATA(pilot);
  const auto& [flight, survey] = *pilot;
  // WHEN localizing with the defaults
  const LocalizationRun run = localizeFlight(flight, survey);
  // THEN the error is that of the same circle flown with TDoA2 (0425-traj1: 0.356 m; here 0.371 m), and the reported
  // σ covers z as on the TDoA2 flights: with the bias counted per pair (F23 before the per-anchor count) the 28 pairs
  // shrank it, and only 25 % / 47 % of the z errors were within 1σ / 2σ
  ASSERT_TRUE(run.metrics);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.40);
  const EstimateChecks c = checks(run, flight, survey);
  EXPECT_GT(c.coverage_2sigma.z(), 0.75);
  EXPECT_GT(c.coverage_1sigma.z(), 0.38);
  EXPECT_GT(c.coverage_2sigma.head<2>().minCoeff(), 0.83);  // 85 / 91 % in x / y
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
}

TEST(Generalization, RealFlightWithALargeBiasWidensItsReportedSigma) {
  // GIVEN the development flight with the largest TDoA bias (0425-traj1: airborne RMSE 0.34 m, of it 0.28 m in z;
  // its residuals that no position explains read a pair-bias level of ≈ 0.39 m against 0.2–0.3 m on the others)
  const std::optional<PilotFlight> pilot = readPilotFlight("0425-traj1");
  UWB_REQUIRE_REAL_DATA(pilot);
  const auto& [flight, survey] = *pilot;
  // WHEN localizing with the bias term as derived (F23d's vertical factor 1), once with the band widened by the
  // level measured in flight and once with the reported pair-bias std fixed at 0.2 m (F23c off); and with the defaults
  LocalizationOptions derived;
  derived.params.output_bias_vertical_scale = 1.0;
  derived.params.fuse_tof = false;  // the TDoA's own band: the downward range (F21) would hold the height
  const LocalizationRun run = localizeFlight(flight, survey, derived);
  LocalizationOptions fixed = derived;
  fixed.params.output_bias_memory_s = 0.0;
  const LocalizationRun run_fixed = localizeFlight(flight, survey, fixed);
  LocalizationOptions defaults_without_tof;
  defaults_without_tof.params.fuse_tof = false;
  const LocalizationRun run_default = localizeFlight(flight, survey, defaults_without_tof);
  // THEN the band measured in flight covers at least half of the errors on every axis at 1σ (fixed: 54 / 52 / 39 %)
  // and 85 % at 2σ, and the estimate itself is the same
  ASSERT_TRUE(run.metrics && run_fixed.metrics && run_default.metrics);
  const EstimateChecks c = checks(run, flight, survey), c_fixed = checks(run_fixed, flight, survey);
  EXPECT_GT(c.coverage_1sigma.minCoeff(), 0.5);
  EXPECT_GT(c.coverage_2sigma.minCoeff(), 0.85);
  EXPECT_LT(c_fixed.coverage_1sigma.z(), 0.45);
  EXPECT_EQ(run.metrics->airborne.rmse_m, run_fixed.metrics->airborne.rmse_m);
  // and with the defaults' vertical factor 0.7, chosen on the 0425 flights without their range with this one among them
  // (filter.md F23d), this flight, the most biased one, is the one left over-confident in z at 1σ (40 %), still within
  // 85–99 % at 2σ (92 %); x and y do not change
  const EstimateChecks c_default = checks(run_default, flight, survey);
  EXPECT_GT(c_default.coverage_1sigma.z(), 0.38);
  EXPECT_LT(c_default.coverage_1sigma.z(), c.coverage_1sigma.z());
  EXPECT_GT(c_default.coverage_2sigma.z(), 0.9);
  EXPECT_LT(c_default.coverage_2sigma.z(), 0.99);
  EXPECT_EQ(c_default.coverage_1sigma.head<2>(), c.coverage_1sigma.head<2>());
  EXPECT_EQ(run_default.metrics->airborne.rmse_m, run.metrics->airborne.rmse_m);
  // and the level it measured is above the reference, reported in the summary; none is measured when it is off
  EXPECT_GT(run.summary.bias_level_m, 0.3);
  EXPECT_GT(run.summary.n_bias_level_windows, 40u);
  EXPECT_TRUE(std::isnan(run_fixed.summary.bias_level_m));
}

TEST(Generalization, SimulatedTdoa3) {
  // GIVEN a simulated figure eight whose tag forms random anchor pairs at 200 Hz (TDoA3, S19b) instead of the
  // neighbour round robin at 400 Hz
  sim::SimParams sp;
  sp.tdoa.tdoa3 = true;
  sp.tdoa.rate_hz = 200.0;
  const sim::SimResult s = sim::simulateFlight(sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kFigureEight, 40.0), sp, 5);
  std::set<std::pair<int, int>> pairs;
  for (const TdoaMeasurement& z : s.flight.tdoa) pairs.insert({std::min(z.id_a, z.id_b), std::max(z.id_a, z.id_b)});
  ASSERT_EQ(pairs.size(), 28u);  // every pair of the 8 anchors
  // WHEN localizing with the defaults
  const LocalizationRun run = localizeFlight(s.flight, s.survey);
  // THEN it is as accurate as the same flight with TDoA2 (0.244 m; TDoA3 0.206 m) and its σ covers
  ASSERT_TRUE(run.metrics);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.26);
  const EstimateChecks c = checks(run, s.flight, s.survey);
  EXPECT_GT(c.coverage_2sigma.minCoeff(), 0.85);
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
}

TEST(Generalization, SimulatedQuietAccelerometerDuringTheClimb) {
  // GIVEN a simulated circle whose accelerometer is quiet (0.04 m/s² per sample instead of 0.15, a soft-mounted or
  // filtered IMU): the steady climb after the take-off and the hover before the circle read as quiet as the motors off
  // WHEN localizing with the defaults
  const LocalizationRun run = localizeSimulated(sim::TrajectoryShape::kCircle, 3, [](sim::SimParams& sp) {
    sp.imu.acc_noise_std_mps2 = 0.04;
  });
  // THEN the climb is not taken for the ground (rest put the climbing body back on the floor and the ZUPT took the
  // climb for accelerometer bias: airborne RMSE 0.73 m, largest error 2.1 m, six rest periods), and the flight is as
  // accurate as with the noisier accelerometer (0.31 m, 0.84 m; this seed's bias field is the hard one)
  ASSERT_NO_FATAL_FAILURE(expectAirborneErrorBelow(run, 0.34, 1.0));
  EXPECT_LE(run.summary.n_rest_periods, 3u);
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
}

TEST(Generalization, SimulatedUncalibratedGyro) {
  // GIVEN a simulated circle whose gyro has a turn-on bias of 0.03 rad/s per axis (1.7 deg/s; a raw MEMS gyro without
  // the Crazyflie's start-up calibration): at rest on the floor it reads above the rest test's 0.03 rad/s rms
  // WHEN localizing with the defaults
  const LocalizationRun run = localizeSimulated(sim::TrajectoryShape::kCircle, 5, [](sim::SimParams& sp) {
    sp.imu.gyro_bias_std_rps = 0.03;
  });
  // THEN rest is found against the gyro's reading in the still levelling window: the start and the landing are on
  // the ground (without the reference: no rest period, the position lost after the landing, 78 % of the TDoA used)
  ASSERT_TRUE(run.metrics);
  EXPECT_EQ(run.summary.n_rest_periods, 2u);
  EXPECT_EQ(run.summary.n_reacquisitions, 0u);
  EXPECT_LT(run.metrics->airborne.rmse_m, 0.25);
  EXPECT_LT(run.metrics->whole.rmse_m, 0.30);
  const LocalizerSummary& sum = run.summary;
  EXPECT_GE(static_cast<double>(sum.n_tdoa_used), 0.9 * sum.n_tdoa_total);
}

TEST(Generalization, SimulatedLandingDoesNotClimbAway) {
  // GIVEN a simulated 16 s still hover whose touchdown the estimate does not follow at once: the floor-biased TDoA
  // (S18) pull it up until the IMU shows the rest about a second later
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {13}, "still-hover-paper");
  const SimScenarioRun& s = scenario(runs, "still-hover-paper-s13");
  // WHEN localizing with the defaults; without range-bias states (F27); and without them and without the floor-level
  // delays (F16f, F16h), with the descent bound (F26, opt-in) and without it
  const LocalizationRun run_default = localizeFlight(s.flight, s.survey);
  LocalizationOptions no_states;
  no_states.params.range_bias_sigma_m = 0.0;
  no_states.params.tdoa_sigma_m = 0.35;
  LocalizationOptions off = no_states;
  off.params.floor_anchor_height_m = 0.0;
  LocalizationOptions on = off;
  on.params.descent_margin_m = 0.3;
  const LocalizationRun run_no_states = localizeFlight(s.flight, s.survey, no_states);
  const LocalizationRun run = localizeFlight(s.flight, s.survey, on);
  const LocalizationRun run_off = localizeFlight(s.flight, s.survey, off);
  // THEN on the ground after the flight the estimate stays below 0.8 m with the defaults and without the range-bias
  // states (the landing's TDoA are taken with the floor's delays where they fit them, F16h). Without those delays it
  // climbs 1.2 m, and the opt-in descent bound (F26), which caught it (0.68 m) while the simulator's gyro turn-on bias
  // tilted the estimate, no longer engages once that bias is learned (F18z, F1: 1.24 m, no bound update;
  // docs/math/filter.md F26 names it). The bound does not change the airborne RMSE
  ASSERT_TRUE(run.metrics && run_off.metrics && run_default.metrics && run_no_states.metrics);
  const EstimateChecks c_off = checks(run_off, s.flight, s.survey);
  EXPECT_LT(checks(run_default, s.flight, s.survey).max_z_on_ground_m, 0.8);
  EXPECT_LT(checks(run_no_states, s.flight, s.survey).max_z_on_ground_m, 0.8);
  EXPECT_GT(c_off.max_z_on_ground_m, 1.0);
  EXPECT_NEAR(run.metrics->airborne.rmse_m, run_off.metrics->airborne.rmse_m, 0.005);
}

}  // namespace
}  // namespace uwb
