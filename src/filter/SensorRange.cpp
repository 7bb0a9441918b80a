/** @file SensorRange.cpp
 *  @brief The sensors' physical ranges (docs/math/filter.md F31).
 */
#include "uwb/filter/SensorRange.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace uwb {

void SensorRangeCount::add(double t_s, double value) {
  if (n++ == 0) first_t_s = t_s;
  const double v = std::isfinite(value) ? std::abs(value) : std::numeric_limits<double>::infinity();
  worst = std::max(worst, v);
}

void SensorRangeCount::merge(const SensorRangeCount& other) {
  if (other.n == 0) return;
  if (n == 0 || other.first_t_s < first_t_s) first_t_s = other.first_t_s;
  n += other.n;
  worst = std::max(worst, other.worst);
}

SensorRangeReport::SensorRangeReport(const EkfParams& params) {
  gyro.limit = params.max_gyro_radps;
  acc.limit = params.max_acc_mps2;
  tdoa.limit = params.max_tdoa_excess_m;
}

void SensorRangeReport::merge(const SensorRangeReport& other) {
  gyro.merge(other.gyro);
  acc.merge(other.acc);
  tdoa.merge(other.tdoa);
}

double rangeNorm(const Vec3& v) {
  if (!v.allFinite()) return std::numeric_limits<double>::infinity();
  return std::hypot(v.x(), v.y(), v.z());  // scaled: no overflow of the squares
}

bool checkImuRange(double t_s, const ImuReading& imu, SensorRangeReport& report) {
  // docs/math/filter.md (F31): ‖ω‖ ≤ ω_max, ‖f‖ ≤ f_max, all finite (a NaN fails every comparison)
  // compared squared on the per-sample path (a NaN or an overflow to inf fails the comparison); the overflow-safe
  // norm only for a sample that is reported
  const double w_lim = report.gyro.limit, f_lim = report.acc.limit;
  const bool gyro_ok = imu.b_gyro_radps.squaredNorm() <= w_lim * w_lim;
  const bool acc_ok = imu.b_acc_mps2.squaredNorm() <= f_lim * f_lim;
  if (gyro_ok && acc_ok && std::isfinite(t_s)) return true;
  if (!gyro_ok) report.gyro.add(t_s, rangeNorm(imu.b_gyro_radps));
  if (!acc_ok) report.acc.add(t_s, rangeNorm(imu.b_acc_mps2));
  return false;
}

bool checkTdoaRange(const TdoaMeasurement& z, const AnchorTable& anchors, SensorRangeReport& report) {
  const Moments3* a = anchors.find(z.id_a);
  const Moments3* b = anchors.find(z.id_b);
  if (!std::isfinite(z.tdoa_m)) {
    report.tdoa.add(z.t_s, z.tdoa_m);
    return false;
  }
  if (!a || !b) return true;  // the update counts an unknown anchor
  // docs/math/filter.md (F31): |z| = |‖p − a_B‖ − ‖p − a_A‖| ≤ ‖a_B − a_A‖ (triangle inequality), plus a margin
  const double excess_m = std::abs(z.tdoa_m) - (b->m - a->m).norm();
  if (excess_m <= report.tdoa.limit) return true;
  report.tdoa.add(z.t_s, excess_m);
  return false;
}

namespace {

std::string worstText(double v, const char* unit) {
  return std::isfinite(v) ? fmt::format("{:.3g} {}", v, unit) : std::string("not finite");
}

}  // namespace

std::vector<std::string> sensorRangeWarnings(const SensorRangeReport& r) {
  std::vector<std::string> w;
  const auto line = [&](const SensorRangeCount& c, const std::string& what, const std::string& bound,
                        const std::string& worst) {
    if (c.n == 0) return;
    w.push_back(fmt::format("skipped {} {} outside the sensor's physical range ({}, filter.md F31): first at "
                            "t = {:.3f} s, worst {}; a sensor or logging fault",
                            c.n, what, bound, c.first_t_s, worst));
  };
  line(r.gyro, r.gyro.n == 1 ? "gyro sample" : "gyro samples",
       fmt::format("‖ω‖ ≤ {:g} rad/s, max_gyro_radps", r.gyro.limit), worstText(r.gyro.worst, "rad/s"));
  line(r.acc, r.acc.n == 1 ? "accelerometer sample" : "accelerometer samples",
       fmt::format("‖f‖ ≤ {:g} m/s², max_acc_mps2", r.acc.limit), worstText(r.acc.worst, "m/s²"));
  line(r.tdoa, "TDoA",
       fmt::format("|z| ≤ anchor-pair baseline + {:g} m, max_tdoa_excess_m", r.tdoa.limit),
       std::isfinite(r.tdoa.worst) ? fmt::format("{:.3g} m beyond the baseline", r.tdoa.worst)
                                   : std::string("not finite"));
  return w;
}

}  // namespace uwb
