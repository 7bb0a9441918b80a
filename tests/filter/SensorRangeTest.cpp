/** @file SensorRangeTest.cpp
 *  @brief The sensors' physical ranges (docs/math/filter.md F31): the checks, their counts and warnings, and the
 *         estimator skipping a sample outside as if it had never come.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "FilterTestUtil.h"
#include "uwb/filter/EkfParamRegistry.h"
#include "uwb/filter/Estimator.h"
#include "uwb/filter/SensorRange.h"

namespace uwb {
namespace {

using ::testing::HasSubstr;
using filtertest::arenaAnchors;

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

ImuReading imu(const Vec3& acc, const Vec3& gyro) { return ImuReading{acc, gyro}; }

TEST(SensorRange, ReadingsWithinTheFullScalePassAndBeyondAreCounted) {
  // GIVEN the default limits
  SensorRangeReport r{EkfParams{}};
  // WHEN readings at the BMI088's full scale on all three axes (±2000 deg/s, ±24 g) are checked
  const double w_fs = 2000.0 * kDegToRad, f_fs = 24.0 * kGravity_mps2;
  EXPECT_TRUE(checkImuRange(1.0, imu(Vec3::Constant(f_fs), Vec3::Constant(-w_fs)), r));
  // THEN they pass; a gyro of 1e10 deg/s, an accelerometer of 1e30 m/s² and a NaN do not, each counted per sensor
  EXPECT_FALSE(checkImuRange(20.0, imu(Vec3(0, 0, 9.81), Vec3(0, 0, 1e10 * kDegToRad)), r));
  EXPECT_FALSE(checkImuRange(21.0, imu(Vec3(1e30, 0, 9.81), Vec3::Zero()), r));
  EXPECT_FALSE(checkImuRange(22.0, imu(Vec3(0, 0, 9.81), Vec3(std::nan(""), 0, 0)), r));
  EXPECT_EQ(r.gyro.n, 2u);
  EXPECT_EQ(r.acc.n, 1u);
  EXPECT_EQ(r.gyro.first_t_s, 20.0);
  EXPECT_EQ(r.acc.first_t_s, 21.0);
  EXPECT_TRUE(std::isinf(r.gyro.worst));  // the NaN is the worst
  EXPECT_NEAR(r.acc.worst, 1e30, 1e16);
}

TEST(SensorRange, TheNormOfAHugeReadingDoesNotOverflow) {
  // GIVEN a gyro reading of 1e308 deg/s on one axis (1.7e306 rad/s: its square overflows)
  const Vec3 w(0.0, 0.0, 1e308 * kDegToRad);
  // WHEN its norm is taken THEN it is the finite value, and a reading with an infinite component is +∞
  EXPECT_NEAR(rangeNorm(w) / (1e308 * kDegToRad), 1.0, 1e-12);
  EXPECT_TRUE(std::isinf(rangeNorm(Vec3(0, std::numeric_limits<double>::infinity(), 0))));
}

TEST(SensorRange, ATdoaLongerThanItsBaselineIsNoRangeDifference) {
  // GIVEN the arena anchors and the default margin of 1 m
  const AnchorTable anchors = arenaAnchors();
  SensorRangeReport r{EkfParams{}};
  const double baseline = (anchors.find(1)->m - anchors.find(0)->m).norm();
  // WHEN TDoA of the pair (0, 1) at the baseline, just inside and beyond the margin, and non-finite are checked
  EXPECT_TRUE(checkTdoaRange({1.0, 0, 1, baseline}, anchors, r));
  EXPECT_TRUE(checkTdoaRange({1.0, 0, 1, -(baseline + 0.99)}, anchors, r));
  EXPECT_FALSE(checkTdoaRange({2.0, 0, 1, baseline + 1.01}, anchors, r));
  EXPECT_FALSE(checkTdoaRange({3.0, 1, 0, -1e30}, anchors, r));
  EXPECT_FALSE(checkTdoaRange({4.0, 1, 0, std::numeric_limits<double>::quiet_NaN()}, anchors, r));
  // THEN the ones beyond are counted with the first stamp and the worst excess; an unknown anchor is left to the update
  EXPECT_TRUE(checkTdoaRange({5.0, 0, 99, 1e30}, anchors, r));
  EXPECT_EQ(r.tdoa.n, 3u);
  EXPECT_EQ(r.tdoa.first_t_s, 2.0);
  EXPECT_TRUE(std::isinf(r.tdoa.worst));
  EXPECT_EQ(r.gyro.n + r.acc.n, 0u);
}

TEST(SensorRange, OneWarningPerSensorWithCountBoundFirstStampAndWorstValue) {
  // GIVEN one gyro sample of 1e10 deg/s at 20 s and three accelerometer samples of 1e30 m/s²
  SensorRangeReport r{EkfParams{}};
  checkImuRange(20.0, imu(Vec3(0, 0, 9.81), Vec3(0, 0, 1e10 * kDegToRad)), r);
  for (int k = 0; k < 3; ++k) checkImuRange(25.0 + k, imu(Vec3(0, 0, 1e30), Vec3::Zero()), r);
  // WHEN the warnings are made
  const std::vector<std::string> w = sensorRangeWarnings(r);
  // THEN there is one per sensor out of range, naming the count, the bound, the first stamp and the worst value
  ASSERT_EQ(w.size(), 2u);
  EXPECT_THAT(w[0], HasSubstr("skipped 1 gyro sample outside the sensor's physical range (‖ω‖ ≤ 70 rad/s"));
  EXPECT_THAT(w[0], HasSubstr("first at t = 20.000 s, worst 1.75e+08 rad/s"));
  EXPECT_THAT(w[1], HasSubstr("skipped 3 accelerometer samples"));
  EXPECT_THAT(w[1], HasSubstr("first at t = 25.000 s, worst 1e+30 m/s²"));
  EXPECT_TRUE(sensorRangeWarnings(SensorRangeReport{EkfParams{}}).empty());
}

TEST(SensorRange, CountsOfARestartedEstimatorAddUp) {
  // GIVEN two reports, the later one with an earlier first stamp
  SensorRangeReport a{EkfParams{}}, b{EkfParams{}};
  checkImuRange(30.0, imu(Vec3::Zero(), Vec3(100, 0, 0)), a);
  checkImuRange(5.0, imu(Vec3::Zero(), Vec3(200, 0, 0)), b);
  // WHEN merged THEN the counts add, the first stamp and the worst value are the extremes
  a.merge(b);
  EXPECT_EQ(a.gyro.n, 2u);
  EXPECT_EQ(a.gyro.first_t_s, 5.0);
  EXPECT_EQ(a.gyro.worst, 200.0);
}

TEST(SensorRange, TheLimitsAreParametersWithTheirChecks) {
  // GIVEN the parameter registry WHEN the limits are looked up THEN each is there, and a limit ≤ 0 is refused
  for (const char* name : {"max_gyro_radps", "max_acc_mps2", "max_tdoa_excess_m"})
    EXPECT_NO_THROW(ekfParamInfo(name)) << name;
  EkfParams p;
  p.max_gyro_radps = 0.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = EkfParams{};
  p.max_acc_mps2 = std::nan("");
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = EkfParams{};
  p.max_tdoa_excess_m = -1.0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

TEST(SensorRange, TheEstimatorSkipsASampleOutsideAsIfItHadNeverCome) {
  // GIVEN a synthetic take-off log, run once as it is and once with a gyro sample of 1e10 deg/s, an accelerometer
  // sample of 1e30 m/s² and a TDoA of 1e30 m inserted between its events in flight
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = 6.0;
  const SensorLog log = filtertest::takeoffLog(spec);
  const EkfParams p;
  Estimator clean(p, arenaAnchors()), faulty(p, arenaAnchors());
  SensorEventCursor cursor(log);
  bool inserted = false;
  for (SensorEvent ev; cursor.next(ev);) {
    for (Estimator* e : {&clean, &faulty}) {
      if (ev.kind == SensorEvent::Kind::kImu) e->addImu(ev.t_s, log.imu[ev.index].imu);
      else e->addTdoa(log.tdoa[ev.index]);
    }
    if (!inserted && ev.t_s > 4.0 && ev.kind == SensorEvent::Kind::kImu) {
      // WHEN the bad samples arrive at the stamp of the last good one
      faulty.addImu(ev.t_s, imu(Vec3(0, 0, 9.81), Vec3(0, 0, 1e10 * kDegToRad)));
      faulty.addImu(ev.t_s, imu(Vec3(0, 0, 1e30), Vec3::Zero()));
      faulty.addTdoa({ev.t_s, 0, 1, 1e30});
      inserted = true;
    }
  }
  // THEN the estimate is the clean one bit for bit, and the samples are counted per sensor
  ASSERT_TRUE(inserted);
  ASSERT_TRUE(clean.ready());
  EXPECT_EQ(faulty.state().w_p_b, clean.state().w_p_b);
  EXPECT_EQ(faulty.state().w_q_b.coeffs(), clean.state().w_q_b.coeffs());
  EXPECT_EQ(faulty.phase(), clean.phase());
  const SensorRangeReport& r = faulty.summary().sensor_range;
  EXPECT_EQ(r.gyro.n, 1u);
  EXPECT_EQ(r.acc.n, 1u);
  EXPECT_EQ(r.tdoa.n, 1u);
  EXPECT_EQ(clean.summary().sensor_range.total(), 0u);
}

}  // namespace
}  // namespace uwb
