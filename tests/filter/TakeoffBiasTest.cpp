/** @file TakeoffBiasTest.cpp
 *  @brief The thrust-axis accelerometer bias is re-opened at take-off (docs/math/filter.md F20): on a synthetic
 *         flight whose accelerometer z reads a different bias once the motors run, the in-flight bias is learned
 *         within seconds with the default take-off inflation and not without it.
 */
#include <gtest/gtest.h>

#include <cmath>

#include "FilterTestUtil.h"
#include "uwb/filter/TdoaLocalizer.h"

namespace uwb {
namespace {

using filtertest::arenaAnchors;

/// IMU at 1 kHz whose z axis reads bias_ground_mps2 before the climb and bias_flight_mps2 from the climb on
/// (vibration noise as in flight); TDoA on the neighbour pairs at 400 Hz with white noise.
SensorLog makeLog(double bias_ground_mps2, double bias_flight_mps2, double duration_s, unsigned seed) {
  filtertest::TakeoffLogSpec spec;
  spec.duration_s = duration_s;
  spec.seed = seed;
  spec.acc_noise_mps2 = 0.5;
  spec.gyro_noise_radps = 0.08;
  spec.tdoa_noise_m = 0.15;
  spec.acc_bias_z = [=](double t) { return t < 1.9 ? bias_ground_mps2 : bias_flight_mps2; };
  return filtertest::takeoffLog(spec);
}

/// Mean estimated z accelerometer bias over [t0, t1].
double meanBiasZ(const LocalizerResult& r, double t0, double t1) {
  double sum = 0.0;
  int n = 0;
  for (const LocalizerEstimate& e : r.estimates)
    if (e.t_s >= t0 && e.t_s <= t1) {
      sum += e.x.b_acc_bias.z();
      ++n;
    }
  return n ? sum / n : std::nan("");
}

TEST(TakeoffBias, InFlightThrustAxisBiasIsLearnedAfterTakeoff) {
  // GIVEN a flight whose accelerometer z bias steps from +0.02 to −0.08 m/s² when the motors spin up
  // (the step seen on util-pilot, F20)
  const SensorLog log = makeLog(0.02, -0.08, 14.0, 11);
  EkfParams with;  // defaults: takeoff_acc_bias_sigma_mps2 = 0.1
  ASSERT_GT(with.takeoff_acc_bias_sigma_mps2, 0.0);
  EkfParams without = with;
  without.takeoff_acc_bias_sigma_mps2 = 0.0;
  // WHEN localizing with and without the take-off inflation of the bias variance
  const LocalizerResult r_with = TdoaLocalizer(with, arenaAnchors()).run(log);
  const LocalizerResult r_without = TdoaLocalizer(without, arenaAnchors()).run(log);
  ASSERT_FALSE(std::isnan(r_with.summary.takeoff_t_s));
  // THEN the ground estimate is near the ground bias (1.5 s of ZUPTs under 0.5 m/s² vibration: ±0.04) ...
  EXPECT_NEAR(meanBiasZ(r_with, 1.0, 1.8), 0.02, 0.04);
  // ... and in the hover 8–14 s only the inflated filter has followed the step to −0.08 m/s²
  const double b_with = meanBiasZ(r_with, 8.0, 14.0);
  const double b_without = meanBiasZ(r_without, 8.0, 14.0);
  EXPECT_NEAR(b_with, -0.08, 0.03);
  EXPECT_LT(std::abs(b_with + 0.08), std::abs(b_without + 0.08)) << "with " << b_with << ", without " << b_without;
}

TEST(TakeoffBias, ZeroSigmaIsAllowedAndNegativeRejected) {
  EkfParams p;
  p.takeoff_acc_bias_sigma_mps2 = 0.0;
  EXPECT_NO_THROW(p.validate());
  p.takeoff_acc_bias_sigma_mps2 = -0.1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace uwb
