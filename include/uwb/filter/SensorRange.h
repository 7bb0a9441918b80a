/** @file SensorRange.h
 *  @brief Every sensor value checked against the sensor's physical range before the filter sees it
 *         (docs/math/filter.md F31): a sample outside is skipped, counted per sensor with its first stamp and its
 *         worst value, and reported. A gyro reading of 1e10 deg/s or a TDoA longer than its anchor pair's baseline is
 *         no measurement: integrated or gated, it would corrupt the state, or the start-up, silently.
 *
 *  The Estimator checks each event on entry (addImu, addTdoa), so every path (batch localize, predict-bias, stream and
 *  replay, swarm, Python) goes through the same check. ToF readings have their own check already (F21,
 *  `tof_max_range_m`, `LocalizerSummary::n_tof_invalid`).
 *
 *  @code
 *    SensorRangeReport range(params);                 // limits from EkfParams (F31)
 *    if (!checkImuRange(t_s, imu, range)) return;     // skipped and counted
 *    for (const std::string& w : sensorRangeWarnings(range)) std::cerr << w << '\n';
 *  @endcode
 */
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "uwb/filter/EkfParams.h"
#include "uwb/filter/NavState.h"
#include "uwb/filter/TdoaUpdate.h"

namespace uwb {

/// The samples of one sensor outside its range (F31).
struct SensorRangeCount {
  double limit = std::numeric_limits<double>::infinity();  ///< the bound checked (SI units of the sensor)
  std::size_t n = 0;                                        ///< samples outside (skipped)
  double first_t_s = std::numeric_limits<double>::quiet_NaN();  ///< stamp of the first of them [s]
  /// The worst value among them (SI: ‖ω‖ [rad/s], ‖f‖ [m/s²], |z| − baseline [m]); +∞ for a non-finite one
  double worst = 0.0;
  void add(double t_s, double value);
  /// Adds the counts of `other` (same limit), e.g. of an estimator that was started again.
  void merge(const SensorRangeCount& other);
};

/// What the range check found, per sensor (F31).
struct SensorRangeReport {
  SensorRangeCount gyro;  ///< ‖ω‖ ≤ max_gyro_radps
  SensorRangeCount acc;   ///< ‖f‖ ≤ max_acc_mps2
  SensorRangeCount tdoa;  ///< |z| ≤ ‖a_B − a_A‖ + max_tdoa_excess_m (the limit here is the excess)
  SensorRangeReport() = default;
  /// The limits of `params` (max_gyro_radps, max_acc_mps2, max_tdoa_excess_m), no samples counted.
  explicit SensorRangeReport(const EkfParams& params);
  /// IMU samples skipped: one with both readings out counts once for each sensor, but is one sample.
  std::size_t total() const { return gyro.n + acc.n + tdoa.n; }
  void merge(const SensorRangeReport& other);
};

/// (F31) ‖v‖ of a 3-vector without overflow (1e308 stays finite where it can); +∞ when a component is not finite.
double rangeNorm(const Vec3& v);

/// (F31) The IMU sample is inside both sensors' ranges: finite, ‖ω‖ ≤ ω_max and ‖f‖ ≤ f_max. When not, it is counted
/// in `report` (per sensor out of range) and false is returned: the caller skips the sample.
bool checkImuRange(double t_s, const ImuReading& imu, SensorRangeReport& report);

/// (F31) The TDoA is inside its physical range: finite and |z| ≤ ‖a_B − a_A‖ + margin (a range difference cannot
/// exceed the distance between the two anchors, triangle inequality). A TDoA naming an anchor outside `anchors`
/// passes (the update counts it as unknown). When not, it is counted in `report` and false is returned.
bool checkTdoaRange(const TdoaMeasurement& z, const AnchorTable& anchors, SensorRangeReport& report);

/// One warning per sensor with samples skipped: the count, the bound, the first stamp and the worst value, e.g.
/// "skipped 1 gyro sample outside the sensor's physical range (‖ω‖ ≤ 70 rad/s, max_gyro_radps, filter.md F31): first
/// at t = 20.000 s, worst 1.75e+08 rad/s; a sensor or logging fault". Empty when nothing was skipped.
std::vector<std::string> sensorRangeWarnings(const SensorRangeReport& report);

}  // namespace uwb
