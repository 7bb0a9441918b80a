/** @file FlightModeTest.cpp
 *  @brief The flight-mode supervisor: every sensor's evidence, bounded by its trust (docs/math/filter.md F29).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "uwb/filter/FlightMode.h"

namespace uwb {
namespace {

constexpr double kImuDt_s = 0.001;
constexpr double kTdoaDt_s = 0.0025;
constexpr double kTofDt_s = 0.04;  // the Flow deck's 25 Hz

/// A supervisor started in `mode`, its clock from t = 0, and the noise of the TDoA heights seeded by `seed`.
struct SupervisorRun {
  SupervisorRun(FlightMode mode, unsigned seed) : rng(seed) { s.reset(mode); }

  /// Feeds `duration_s` of IMU evidence (1 kHz) and TDoA (400 Hz) whose heights scatter about `tdoa_height_m` with
  /// `spread_m` (the estimate sits at `estimate_height_m`); the vertical gains cycle through ±0.4…0.8. A finite
  /// `tof_height_m` adds a downward range reading it at 25 Hz; NaN heights leave that sensor silent.
  void feed(double duration_s, const ImuModeEvidence& imu, double tdoa_height_m, double spread_m,
            double estimate_height_m, bool settled_in_air = false,
            double tof_height_m = std::numeric_limits<double>::quiet_NaN()) {
    std::normal_distribution<double> n(0.0, 1.0);
    const double gains[] = {0.8, -0.5, 0.4, -0.7, 0.6};
    const double t_end = t + duration_s;
    double t_next_tdoa = t;
    double t_next_tof = t;
    int k = 0;
    while (t < t_end) {
      t += kImuDt_s;
      s.addImu(t, kImuDt_s, imu, settled_in_air);
      if (std::isfinite(tdoa_height_m) && t >= t_next_tdoa) {
        const double g = gains[k++ % 5];
        const double h = tdoa_height_m + spread_m * n(rng);
        const double r = (h - estimate_height_m) * g;
        s.addTdoa(t, r, r, g, estimate_height_m);
        t_next_tdoa += kTdoaDt_s;
      }
      if (std::isfinite(tof_height_m) && t >= t_next_tof) {
        s.addTof(t, tof_height_m);
        t_next_tof += kTofDt_s;
      }
      s.decide(t);
    }
  }

  FlightModeSupervisor s;
  std::mt19937 rng;
  double t = 0.0;
};

constexpr double kNoTdoa = std::numeric_limits<double>::quiet_NaN();

TEST(FlightMode, TheImuAloneDecidesWithoutOtherEvidence) {
  // GIVEN a supervisor in the air and an IMU at rest, then moving, then shaking on the floor
  SupervisorRun run(FlightMode::kAirborne, 1);
  FlightModeSupervisor& s = run.s;
  // WHEN the IMU reads rest for 0.1 s
  run.feed(0.1, ImuModeEvidence{true, false, false, 0.0}, kNoTdoa, 0.0, 0.0);
  // THEN the body is at rest on the floor
  EXPECT_EQ(s.mode(), FlightMode::kRest);
  EXPECT_TRUE(s.status() & kModeRest);
  EXPECT_TRUE(s.status() & kImuSaysRest);
  // WHEN it shakes with the motors running
  run.feed(0.1, ImuModeEvidence{false, true, false, 0.1}, kNoTdoa, 0.0, 0.0);
  EXPECT_EQ(s.mode(), FlightMode::kContact);
  // WHEN a climb is seen
  run.feed(0.1, ImuModeEvidence{false, false, true, 0.0}, kNoTdoa, 0.0, 0.0);
  // THEN airborne, the IMU's log-odds at their bound
  EXPECT_EQ(s.mode(), FlightMode::kAirborne);
  EXPECT_DOUBLE_EQ(s.imuLogOdds(), FlightModeParams{}.imu_max_log_odds);
  EXPECT_EQ(s.tdoaOverrules(), 0);
}

TEST(FlightMode, TdoaThatPutTheTagHighOverruleTheImusFloorContact) {
  // GIVEN the IMU reads floor contact (a drone whose gyro shakes in flight) and the estimate sits on the floor
  SupervisorRun run(FlightMode::kContact, 2);
  FlightModeSupervisor& s = run.s;
  const ImuModeEvidence contact{false, true, false, 0.3 * 0.3};
  run.feed(0.3, contact, kNoTdoa, 0.0, 0.0);
  ASSERT_EQ(s.mode(), FlightMode::kContact);
  // WHEN the TDoA put the tag 1.2 m above the floor (residual spread 0.15 m)
  run.feed(1.0, contact, 1.2, 0.15, 0.0);
  // THEN the mode is airborne, against the IMU, and the status word says so
  EXPECT_EQ(s.mode(), FlightMode::kAirborne);
  EXPECT_NEAR(s.tdoaHeight(), 1.2, 0.1);
  EXPECT_GT(s.tdoaLogOdds(), 10.0);
  EXPECT_LT(s.imuLogOdds(), 0.0);
  EXPECT_TRUE(s.status() & kTdoaOverrulesImu);
  EXPECT_TRUE(s.status() & kTdoaSaysAirborne);
  EXPECT_EQ(s.tdoaOverrules(), 1);
}

TEST(FlightMode, FloorTdoaThatScatterByMetresDoNotLiftTheBody) {
  // GIVEN a body in floor contact whose TDoA carry a floor-level bias: heights about 0.4 m, scattered by 0.8 m
  SupervisorRun run(FlightMode::kContact, 3);
  FlightModeSupervisor& s = run.s;
  // WHEN 3 s of them arrive
  run.feed(3.0, ImuModeEvidence{false, true, false, 0.5 * 0.5}, 0.4, 0.8, 0.0);
  // THEN the IMU's floor holds: the scattered window's factor stays below the IMU's bound
  EXPECT_EQ(s.mode(), FlightMode::kContact);
  EXPECT_LT(s.tdoaLogOdds(), FlightModeParams{}.imu_max_log_odds - FlightModeParams{}.hysteresis_log_odds);
  EXPECT_GT(s.tdoaHeightSpread(), 0.1);
}

TEST(FlightMode, FloorTdoaCannotHoldAClimbOnTheFloor) {
  // GIVEN a body on the floor whose TDoA say so precisely
  SupervisorRun run(FlightMode::kContact, 4);
  FlightModeSupervisor& s = run.s;
  run.feed(1.0, ImuModeEvidence{false, true, false, 0.5 * 0.5}, 0.0, 0.05, 0.0);
  EXPECT_DOUBLE_EQ(s.tdoaLogOdds(), -FlightModeParams{}.tdoa_max_floor_log_odds);
  // WHEN the take-off detector sees a climb (the TDoA window still on the floor)
  run.feed(0.05, ImuModeEvidence{false, false, true, 0.0}, 0.0, 0.05, 0.0);
  // THEN airborne at once: the floor's TDoA weigh at most tdoa_max_floor_log_odds
  EXPECT_EQ(s.mode(), FlightMode::kAirborne);
}

TEST(FlightMode, DoubtIsCountedWhileTheImuHoldsTheFloorAgainstTheTdoa) {
  // GIVEN a body at rest by the IMU whose TDoA put it 0.35 m up (not enough to overrule the IMU)
  SupervisorRun run(FlightMode::kRest, 5);
  FlightModeSupervisor& s = run.s;
  run.feed(2.0, ImuModeEvidence{true, false, false, 0.0}, 0.35, 0.05, 0.0);
  // THEN it stays at rest, and the doubt is counted with the TDoA's height
  EXPECT_EQ(s.mode(), FlightMode::kRest);
  EXPECT_GT(s.tdoaLogOdds(), FlightModeParams{}.tdoa_max_floor_log_odds);
  EXPECT_GT(s.doubtedFloorTime(), 1.0);
  EXPECT_NEAR(s.doubtedFloorMaxHeight(), 0.35, 0.05);
}

TEST(FlightMode, ADownwardRangeThatReadsAHeightLiftsTheImusFloorContact) {
  // GIVEN floor contact by the IMU (a drone whose gyro shakes in flight) and a range that reads the floor
  SupervisorRun run(FlightMode::kContact, 7);
  FlightModeSupervisor& s = run.s;
  const ImuModeEvidence contact{false, true, false, 0.3 * 0.3};
  run.feed(0.5, contact, kNoTdoa, 0.0, 0.0, false, 0.02);
  // THEN the floor holds; a range near zero is weak floor evidence (an obstacle under a hovering drone reads so)
  EXPECT_EQ(s.mode(), FlightMode::kContact);
  EXPECT_DOUBLE_EQ(s.tofLogOdds(), -FlightModeParams{}.tdoa_max_floor_log_odds);
  EXPECT_NEAR(s.tofHeight(), 0.02, 1e-9);
  // WHEN the range reads 0.5 m, the IMU unchanged
  run.feed(0.5, contact, kNoTdoa, 0.0, 0.0, false, 0.5);
  // THEN airborne against the IMU (F29f), the status word says why
  EXPECT_EQ(s.mode(), FlightMode::kAirborne);
  EXPECT_GT(s.tofLogOdds(), FlightModeParams{}.imu_max_log_odds + FlightModeParams{}.hysteresis_log_odds);
  EXPECT_TRUE(s.status() & kTofSaysAirborne);
  EXPECT_TRUE(s.status() & kTdoaOverrulesImu);
  EXPECT_DOUBLE_EQ(s.tdoaLogOdds(), 0.0);
}

TEST(FlightMode, ADownwardRangeDoesNotOverruleRestAndStopsCountingWhenItStops) {
  // GIVEN a body at rest by the IMU (motors off) whose range reads 1 m (carried over a table, a ledge)
  SupervisorRun run(FlightMode::kRest, 8);
  FlightModeSupervisor& s = run.s;
  const ImuModeEvidence rest{true, false, false, 0.0};
  run.feed(1.0, rest, kNoTdoa, 0.0, 0.0, false, 1.0);
  // THEN rest holds: its bound is above the range's
  EXPECT_EQ(s.mode(), FlightMode::kRest);
  EXPECT_GT(s.tofLogOdds(), 10.0);
  // WHEN the range stops reporting (out of range) for 1.5 s
  run.feed(1.5, rest, kNoTdoa, 0.0, 0.0, false, kNoTdoa);
  // THEN its window has aged out: it says nothing
  EXPECT_DOUBLE_EQ(s.tofLogOdds(), 0.0);
  EXPECT_TRUE(std::isnan(s.tofHeight()));
  EXPECT_FALSE(s.status() & kTofSaysAirborne);
}

TEST(FlightMode, TheAirborneShakingLevelIsLearnedFromTheFlight) {
  // GIVEN the prior level: shaking of 0.3 rad/s rms stands out as floor contact
  SupervisorRun run(FlightMode::kAirborne, 6);
  FlightModeSupervisor& s = run.s;
  EXPECT_TRUE(s.shakingStandsOut(0.3 * 0.3));
  EXPECT_FALSE(s.status() & kAirShakeLearned);
  // WHEN the flight shakes at 0.3 rad/s while settled in the air
  run.feed(1.0, ImuModeEvidence{false, false, false, 0.3 * 0.3}, kNoTdoa, 0.0, 1.0, true);
  // THEN that shaking is the flight's, not floor contact; the idle shaking of another drone's floor (0.7) still is
  EXPECT_FALSE(s.shakingStandsOut(0.3 * 0.3));
  EXPECT_TRUE(s.shakingStandsOut(0.7 * 0.7));
  EXPECT_TRUE(s.status() & kAirShakeLearned);
  // AND the level decays back towards the prior when the flight is quiet, never below it
  run.feed(30.0, ImuModeEvidence{false, false, false, 0.0}, kNoTdoa, 0.0, 1.0, true);
  EXPECT_DOUBLE_EQ(s.airShakeLevel(), FlightModeParams{}.air_shake_prior_ms);
}

TEST(FlightMode, ABadWindowSaysNothing) {
  // GIVEN TDoA without vertical sensitivity or with non-finite values
  FlightModeSupervisor s;
  s.reset(FlightMode::kRest);
  for (int k = 0; k < 200; ++k) {
    s.addTdoa(0.001 * k, 1.0, 1.0, 0.05, 0.0);  // gain below min_vertical_gain
    s.addTdoa(0.001 * k, std::nan(""), 0.0, 0.5, 0.0);
  }
  // THEN the window is not valid and its factor is 0
  EXPECT_FALSE(s.status() & kTdoaHeightValid);
  EXPECT_DOUBLE_EQ(s.tdoaLogOdds(), 0.0);
  EXPECT_TRUE(std::isnan(s.tdoaHeight()));
}

TEST(FlightMode, DoubtIsCountedOnlyWhileTdoaKeepComing) {
  // GIVEN floor contact by the IMU while TDoA with scattered heights put the tag above the floor: doubt is counted
  SupervisorRun run(FlightMode::kContact, 5);
  FlightModeSupervisor& s = run.s;
  const ImuModeEvidence contact{false, true, false, 0.5 * 0.5};
  run.feed(1.0, contact, 1.4, 1.5, 0.0);
  ASSERT_EQ(s.mode(), FlightMode::kContact);
  ASSERT_GT(s.tdoaLogOdds(), FlightModeParams{}.tdoa_max_floor_log_odds);
  const double doubted = s.doubtedFloorTime();
  ASSERT_GT(doubted, 0.5);
  // WHEN the TDoA pause for 3 s (a landing's re-acquisition batch) while the IMU still reads contact
  run.feed(3.0, contact, kNoTdoa, 0.0, 0.0);
  // THEN the doubt stops growing within a fifth of the window's forgetting time (the window keeps its weight in the
  // mode: F29e's floor check is decided on it)
  EXPECT_LT(s.doubtedFloorTime() - doubted, 0.2 * FlightModeParams{}.tdoa_window_s + 0.01);
  EXPECT_GT(s.tdoaLogOdds(), FlightModeParams{}.tdoa_max_floor_log_odds);
  EXPECT_EQ(s.mode(), FlightMode::kContact);
  // WHEN they come again
  run.feed(0.5, contact, 1.4, 1.5, 0.0);
  // THEN the doubt grows again
  EXPECT_GT(s.doubtedFloorTime() - doubted, 0.3);
}

TEST(FlightMode, ParamsAreValidated) {
  FlightModeParams p;
  p.air_max_height_m = p.air_min_height_m;
  EXPECT_THROW(FlightModeSupervisor{p}, std::invalid_argument);
  p = FlightModeParams{};
  p.air_shake_ratio = 0.5;
  EXPECT_THROW(FlightModeSupervisor{p}, std::invalid_argument);
}

}  // namespace
}  // namespace uwb
