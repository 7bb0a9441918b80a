/** @file SensorEventsTest.cpp
 *  @brief Merging IMU and TDoA streams: ordering, duplicates, out-of-order stamps, gaps (docs/math/filter.md F17).
 */
#include <gtest/gtest.h>

#include <cmath>

#include "uwb/filter/SensorEvents.h"

namespace uwb {
namespace {

TimedImu imuAt(double t) {
  TimedImu s;
  s.t_s = t;
  return s;
}

TEST(SensorEvents, MergesInTimeOrderWithImuFirstOnTies) {
  // GIVEN two interleaved streams with one equal stamp
  SensorLog log;
  log.imu = {imuAt(0.0), imuAt(0.001), imuAt(0.002)};
  log.tdoa = {{0.0005, 0, 1, 0.1}, {0.002, 1, 2, 0.2}};
  // WHEN merging
  MergeReport rep;
  const std::vector<SensorEvent> ev = mergeSensorStreams(log, 0.2, &rep);
  // THEN the events are time-ordered and IMU precedes TDoA at t = 0.002
  ASSERT_EQ(ev.size(), 5u);
  for (std::size_t i = 1; i < ev.size(); ++i) EXPECT_LE(ev[i - 1].t_s, ev[i].t_s);
  EXPECT_EQ(ev[3].kind, SensorEvent::Kind::kImu);
  EXPECT_EQ(ev[4].kind, SensorEvent::Kind::kTdoa);
  EXPECT_TRUE(rep.notes().empty());
}

TEST(SensorEvents, DuplicatesAreDroppedAndCounted) {
  // GIVEN a repeated IMU stamp and an exactly repeated TDoA row, plus a same-stamp TDoA of another pair
  SensorLog log;
  log.imu = {imuAt(0.0), imuAt(0.001), imuAt(0.001), imuAt(0.002)};
  log.tdoa = {{0.001, 0, 1, 0.1}, {0.001, 0, 1, 0.1}, {0.001, 1, 2, 0.3}};
  // WHEN merging
  MergeReport rep;
  const std::vector<SensorEvent> ev = mergeSensorStreams(log, 0.2, &rep);
  // THEN one IMU and one TDoA duplicate are dropped, the other pair at the same stamp is kept
  EXPECT_EQ(rep.n_imu_duplicate, 1u);
  EXPECT_EQ(rep.n_tdoa_duplicate, 1u);
  EXPECT_EQ(log.imu.size(), 3u);
  EXPECT_EQ(log.tdoa.size(), 2u);
  EXPECT_EQ(ev.size(), 5u);
  EXPECT_EQ(rep.notes().size(), 2u);
}

TEST(SensorEvents, OutOfOrderStampsAreSortedAndCounted) {
  // GIVEN streams with swapped samples
  SensorLog log;
  log.imu = {imuAt(0.0), imuAt(0.002), imuAt(0.001), imuAt(0.003)};
  log.tdoa = {{0.0025, 0, 1, 0.1}, {0.0015, 1, 2, 0.2}};
  // WHEN merging
  MergeReport rep;
  const std::vector<SensorEvent> ev = mergeSensorStreams(log, 0.2, &rep);
  // THEN they are counted and the result is ordered
  EXPECT_EQ(rep.n_imu_out_of_order, 1u);
  EXPECT_EQ(rep.n_tdoa_out_of_order, 1u);
  for (std::size_t i = 1; i < ev.size(); ++i) EXPECT_LE(ev[i - 1].t_s, ev[i].t_s);
  EXPECT_DOUBLE_EQ(log.imu[1].t_s, 0.001);
}

TEST(SensorEvents, GapsAndNonFiniteSamplesAreReported) {
  // GIVEN an IMU gap of 0.5 s and a NaN TDoA
  SensorLog log;
  log.imu = {imuAt(0.0), imuAt(0.001), imuAt(0.501)};
  log.tdoa = {{0.1, 0, 1, std::nan("")}, {0.2, 0, 1, 0.1}};
  // WHEN merging with a 0.2 s gap limit
  MergeReport rep;
  const std::vector<SensorEvent> ev = mergeSensorStreams(log, 0.2, &rep);
  // THEN
  EXPECT_EQ(rep.n_imu_gaps, 1u);
  EXPECT_NEAR(rep.max_imu_gap_s, 0.5, 1e-12);
  EXPECT_EQ(rep.n_nonfinite, 1u);
  EXPECT_EQ(ev.size(), 4u);
}

TEST(SensorEvents, PairsAccAndGyroByZeroOrderHold) {
  // GIVEN acc at 1 kHz and gyro slightly later
  std::vector<TimedVec3> acc = {{0.000, Vec3(0, 0, 9.8)}, {0.001, Vec3(0, 0, 9.8)}, {0.002, Vec3(0, 0, 9.8)}};
  std::vector<TimedVec3> gyro = {{0.0001, Vec3(1, 0, 0)}, {0.0011, Vec3(2, 0, 0)}, {0.0021, Vec3(3, 0, 0)}};
  // WHEN pairing
  const std::vector<TimedImu> imu = pairImuStreams(acc, gyro);
  // THEN the gyro value is the latest at or before the acc stamp (the first one before any)
  ASSERT_EQ(imu.size(), 3u);
  EXPECT_DOUBLE_EQ(imu[0].imu.b_gyro_radps.x(), 1.0);
  EXPECT_DOUBLE_EQ(imu[1].imu.b_gyro_radps.x(), 1.0);
  EXPECT_DOUBLE_EQ(imu[2].imu.b_gyro_radps.x(), 2.0);
}

TEST(SensorEvents, CleanLogMergesInPlaceLikeTheCleaningMerge) {
  // GIVEN a clean log with a gap, equal stamps and ToF
  SensorLog log;
  for (int i = 0; i < 20; ++i) log.imu.push_back(imuAt(0.001 * i + (i >= 10 ? 0.5 : 0.0)));
  log.tdoa = {{0.0005, 0, 1, 0.1}, {0.002, 1, 2, 0.2}, {0.002, 2, 3, 0.3}, {0.6, 0, 1, 0.1}};
  log.tof = {{0.001, 1.0}, {0.51, 1.1}};
  ASSERT_TRUE(sensorLogIsClean(log));
  // WHEN walking it in place with the cursor (as TdoaLocalizer::run does) and through the cleaning merge
  std::vector<SensorEvent> ev_clean;
  SensorEventCursor cursor(log);
  EXPECT_EQ(cursor.firstStamp(), 0.0);
  EXPECT_EQ(cursor.lastStamp(), 0.6);
  for (SensorEvent e; cursor.next(e);) ev_clean.push_back(e);
  MergeReport rep;
  SensorLog copy = log;
  const std::vector<SensorEvent> ev = mergeSensorStreams(copy, 0.2, &rep);
  // THEN the events are the same
  ASSERT_EQ(ev_clean.size(), ev.size());
  for (std::size_t i = 0; i < ev.size(); ++i) {
    EXPECT_EQ(ev_clean[i].t_s, ev[i].t_s);
    EXPECT_EQ(ev_clean[i].kind, ev[i].kind);
    EXPECT_EQ(ev_clean[i].index, ev[i].index);
  }
  // AND the one-pass check-and-report gives the cleaning merge's report
  const std::optional<MergeReport> rep_one_pass = cleanSensorLogReportIfClean(log, 0.2);
  ASSERT_TRUE(rep_one_pass.has_value());
  EXPECT_EQ(rep_one_pass->n_imu_gaps, 1u);
  EXPECT_EQ(rep_one_pass->n_imu_in, rep.n_imu_in);
  EXPECT_EQ(rep_one_pass->n_tdoa_in, rep.n_tdoa_in);
  EXPECT_EQ(rep_one_pass->n_tof_in, rep.n_tof_in);
  EXPECT_EQ(rep_one_pass->n_imu_gaps, rep.n_imu_gaps);
  EXPECT_EQ(rep_one_pass->n_tdoa_gaps, rep.n_tdoa_gaps);
  EXPECT_EQ(rep_one_pass->max_imu_gap_s, rep.max_imu_gap_s);
  EXPECT_EQ(rep_one_pass->max_tdoa_gap_s, rep.max_tdoa_gap_s);
  EXPECT_EQ(rep_one_pass->notes(), rep.notes());
}

TEST(SensorEvents, LogsThatNeedCleaningAreNotClean) {
  // GIVEN a clean log, and variants with each defect the cleaning merge repairs
  SensorLog clean;
  clean.imu = {imuAt(0.0), imuAt(0.001)};
  clean.tdoa = {{0.0, 0, 1, 0.1}, {0.0, 1, 2, 0.1}};
  clean.tof = {{0.0, 1.0}};
  EXPECT_TRUE(sensorLogIsClean(clean));
  EXPECT_TRUE(cleanSensorLogReportIfClean(clean, 0.2).has_value());
  SensorLog dup_imu = clean;
  dup_imu.imu[1].t_s = 0.0;
  SensorLog nan_acc = clean;
  nan_acc.imu[0].imu.b_acc_mps2.y() = std::nan("");
  SensorLog inf_gyro = clean;
  inf_gyro.imu[1].imu.b_gyro_radps.z() = INFINITY;
  SensorLog dup_tdoa = clean;
  dup_tdoa.tdoa[1] = dup_tdoa.tdoa[0];
  SensorLog unordered_tdoa = clean;
  unordered_tdoa.tdoa[0].t_s = 0.01;
  SensorLog nan_tdoa = clean;
  nan_tdoa.tdoa[1].tdoa_m = std::nan("");
  SensorLog tof_nan_stamp = clean;
  tof_nan_stamp.tof[0].t_s = std::nan("");
  // THEN none of them is clean
  for (const SensorLog* l : {&dup_imu, &nan_acc, &inf_gyro, &dup_tdoa, &unordered_tdoa, &nan_tdoa, &tof_nan_stamp})
  {
    EXPECT_FALSE(sensorLogIsClean(*l));
    EXPECT_FALSE(cleanSensorLogReportIfClean(*l, 0.2).has_value());
  }
}

}  // namespace
}  // namespace uwb
