/** @file ImuSignatureTest.cpp
 *  @brief Another drone's IMU signature on a flight (docs/math/simulation.md S24).
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/ImuSignature.h"

namespace uwb::sim {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

/// RMS of the norm of the gyro minus its 10 ms moving mean, over the samples in [t0, t1].
double highPassRms(const std::vector<ImuSample>& s, double t0, double t1) {
  double sq = 0.0;
  int n = 0;
  for (std::size_t i = 5; i + 5 < s.size(); ++i) {
    if (s[i].t_s < t0 || s[i].t_s > t1) continue;
    Vec3 mean = Vec3::Zero();
    for (std::size_t k = i - 5; k < i + 5; ++k) mean += s[k].b_value;
    sq += (s[i].b_value - mean / 10.0).squaredNorm();
    ++n;
  }
  return std::sqrt(sq / n);
}

SimResult flight() { return simulateFlight(makeScenario(paperAnchors(), TrajectoryShape::kCircle, 30.0), SimParams{}, 7); }

TEST(ImuSignature, RotorVibrationInFlightAndAQuietFloor) {
  // GIVEN a simulated flight from the floor, and the signature of a drone that shakes in flight (20°/s) with its
  // motors off on the floor
  SimResult sim = flight();
  const Flight before = sim.flight;
  ImuSignature sig;
  sig.flight_gyro_vib_rms_radps = 20.0 * kDeg;
  sig.flight_acc_vib_rms_mps2 = 0.05;
  sig.floor = FloorImu::kMotorsOff;
  // WHEN applied
  applyImuSignature(sim.flight, sig, 3);
  // THEN the gyro shakes in flight at about the asked RMS (the 10 ms high-pass keeps the 150–240 Hz tones)
  const double t_takeoff = sim.flight.pose.front().t_s + 0.1;
  const double air = highPassRms(sim.flight.gyro, 10.0, 20.0);
  EXPECT_NEAR(air, 20.0 * kDeg, 0.15 * 20.0 * kDeg);
  // AND the floor before the take-off is quiet (a still MEMS gyro)
  EXPECT_LT(highPassRms(sim.flight.gyro, t_takeoff, 0.4), 0.01);
  // AND the other streams are untouched, the IMU keeps its stamps
  EXPECT_EQ(sim.flight.tdoa.size(), before.tdoa.size());
  EXPECT_EQ(sim.flight.tdoa[100].tdoa_m, before.tdoa[100].tdoa_m);
  ASSERT_EQ(sim.flight.gyro.size(), before.gyro.size());
  EXPECT_EQ(sim.flight.gyro[500].t_s, before.gyro[500].t_s);
  // AND the manoeuvres stay: the low-passed signal follows the original within the vibration
  EXPECT_LT((sim.flight.gyro[15000].b_value - before.gyro[15000].b_value).norm(), 4.0 * 20.0 * kDeg);
}

TEST(ImuSignature, RateBiasAndLag) {
  // GIVEN a 1 kHz flight and a 100 Hz IMU with a gyro bias of 3°/s, an accelerometer bias of 0.1 g and a 30 ms lag
  SimResult sim = flight();
  const Flight before = sim.flight;
  ImuSignature sig;
  sig.rate_hz = 100.0;
  sig.gyro_bias_radps = Vec3(3.0 * kDeg, 0.0, 0.0);
  sig.acc_bias_mps2 = Vec3(0.0, 0.0, 0.980665);
  sig.lag_s = 0.03;
  applyImuSignature(sim.flight, sig, 3);
  // THEN one sample in ten remains, the mean of its block plus the bias, stamped 30 ms late
  ASSERT_EQ(sim.flight.gyro.size(), before.gyro.size() / 10);
  Vec3 block = Vec3::Zero();
  for (int k = 0; k < 10; ++k) block += before.gyro[k].b_value;
  EXPECT_NEAR((sim.flight.gyro[0].b_value - (block / 10.0 + sig.gyro_bias_radps)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(sim.flight.gyro[0].t_s, before.gyro[9].t_s + 0.03, 1e-12);
  Vec3 acc_block = Vec3::Zero();
  for (int k = 0; k < 10; ++k) acc_block += before.acc[k].b_value;
  EXPECT_NEAR(sim.flight.acc[0].b_value.z(), acc_block.z() / 10.0 + 0.980665, 1e-12);
}

TEST(ImuSignature, AHandHeldFloorTurnsTheBodyAndGravityWithIt) {
  // GIVEN a simulated flight from the floor without IMU noise, and a hand that wobbles the drone at 20°/s RMS while it
  // is on the floor
  SimResult sim = simulateFlight(makeScenario(paperAnchors(), TrajectoryShape::kCircle, 30.0), SimParams::noiseFree(), 7);
  const Flight before = sim.flight;
  ImuSignature sig;
  sig.floor = FloorImu::kHandHeld;
  sig.floor_gyro_vib_rms_radps = 20.0 * kDeg;
  applyImuSignature(sim.flight, sig, 5);
  ASSERT_EQ(sim.flight.gyro.size(), before.gyro.size());
  // THEN, away from the take-off, the gyro's deviation from the plain flight has about the asked RMS
  const double t0 = sim.flight.gyro.front().t_s;
  double sq = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < before.gyro.size(); ++i) {
    const double t = before.gyro[i].t_s;
    if (t < t0 + 0.6 || t > t0 + 3.0) continue;
    sq += (sim.flight.gyro[i].b_value - before.gyro[i].b_value).squaredNorm();
    ++n;
  }
  EXPECT_NEAR(std::sqrt(sq / n), 20.0 * kDeg, 0.3 * 20.0 * kDeg);
  // AND the accelerometer sees gravity turn by the angle the gyro integrates, f' ≈ f − θ × f (S24b), with θ = 0 where
  // the wobble has faded out at the take-off
  const double floor_z = truthFloorLevel(before.pose);
  std::size_t edge = 0;
  while (edge + 1 < before.gyro.size() && truthHeightAt(before.pose, before.gyro[edge].t_s) <= floor_z + sig.air_height_m)
    ++edge;
  ASSERT_GT(before.gyro[edge].t_s, t0 + 3.0);
  Vec3 theta = Vec3::Zero();
  double sq_residual = 0.0, sq_predicted = 0.0;
  for (std::size_t i = edge; i > 0 && before.gyro[i].t_s > before.gyro[edge].t_s - 3.0; --i) {
    const double dt = before.gyro[i].t_s - before.gyro[i - 1].t_s;
    theta -= 0.5 * dt * ((sim.flight.gyro[i].b_value - before.gyro[i].b_value) +
                         (sim.flight.gyro[i - 1].b_value - before.gyro[i - 1].b_value));
    const Vec3 predicted = -theta.cross(before.acc[i - 1].b_value);
    sq_residual += (sim.flight.acc[i - 1].b_value - before.acc[i - 1].b_value - predicted).squaredNorm();
    sq_predicted += predicted.squaredNorm();
  }
  EXPECT_GT(std::sqrt(sq_predicted / 3000.0), 0.05);  // gravity swings by more than 0.05 m/s² RMS (3 s at 1 kHz)
  EXPECT_LT(std::sqrt(sq_residual / sq_predicted), 0.15);  // the still IMU's own noise: ≈ 0.09
  // AND the flight itself is untouched
  const std::size_t mid = before.gyro.size() / 2;
  EXPECT_EQ(sim.flight.gyro[mid].b_value, before.gyro[mid].b_value);
  EXPECT_EQ(sig.label(), "gyro 0°/s, acc 0 g, floor hand-held 20°/s");
}

TEST(ImuSignature, AFasterImuIsInterpolatedBeforeItShakes) {
  // GIVEN a 1 kHz flight and a 2 kHz IMU without vibration
  SimResult sim = flight();
  const Flight before = sim.flight;
  ImuSignature sig;
  sig.rate_hz = 2000.0;
  applyImuSignature(sim.flight, sig, 3);
  // THEN twice the samples, evenly stamped from the first, each between its two neighbours of the log
  ASSERT_NEAR(static_cast<double>(sim.flight.gyro.size()), 2.0 * static_cast<double>(before.gyro.size()), 2.0);
  EXPECT_EQ(sim.flight.gyro.front().t_s, before.gyro.front().t_s);
  EXPECT_NEAR(sim.flight.gyro[1001].t_s - sim.flight.gyro[1000].t_s, 0.0005, 1e-9);
  const Vec3 mid = 0.5 * (before.gyro[500].b_value + before.gyro[501].b_value);
  EXPECT_NEAR((sim.flight.gyro[1001].b_value - mid).norm(), 0.0, 1e-9);
  EXPECT_NEAR((sim.flight.acc[1000].b_value - before.acc[500].b_value).norm(), 0.0, 1e-9);
}

TEST(ImuSignature, TheSameSeedGivesTheSameFlight) {
  SimResult a = flight(), b = flight();
  ImuSignature sig;
  sig.flight_gyro_vib_rms_radps = 0.2;
  sig.floor = FloorImu::kIdle;
  sig.floor_gyro_vib_rms_radps = 0.5;
  applyImuSignature(a.flight, sig, 9);
  applyImuSignature(b.flight, sig, 9);
  for (std::size_t i = 0; i < a.flight.gyro.size(); i += 997) EXPECT_EQ(a.flight.gyro[i].b_value, b.flight.gyro[i].b_value);
  EXPECT_EQ(sig.label(), "gyro 11°/s, acc 0 g, floor idle 29°/s");
}

TEST(ImuSignature, BadInputIsRefused) {
  SimResult sim = flight();
  ImuSignature sig;
  sig.lag_s = -0.01;
  EXPECT_THROW(applyImuSignature(sim.flight, sig, 1), std::invalid_argument);
  Flight no_pose = sim.flight;
  no_pose.pose.clear();
  EXPECT_THROW(applyImuSignature(no_pose, ImuSignature{}, 1), std::invalid_argument);
}

}  // namespace
}  // namespace uwb::sim
