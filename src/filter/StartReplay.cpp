/** @file StartReplay.cpp
 *  @brief The start-up window run again from the multilateration's starting point (docs/math/filter.md F16g).
 */
#include "uwb/filter/StartReplay.h"

#include <limits>

namespace uwb {

StartReplay::StartReplay(const EkfParams& params, std::size_t capacity)
    : base_(params), t_ref_s_(std::numeric_limits<double>::quiet_NaN()) {
  entries_.reserve(capacity);
}

void StartReplay::begin(const Ekf& filter, double t_ref_s) {
  base_ = filter;
  t_ref_s_ = t_ref_s;
  entries_.clear();
  recording_ = true;
  overflow_ = false;
}

void StartReplay::append(const Entry& e) {
  if (!recording_) return;
  if (entries_.size() == entries_.capacity()) {
    overflow_ = true;  // bounded: a window this long is not replayed (F16g)
    return;
  }
  entries_.push_back(e);
}

void StartReplay::recordPredict(const ImuReading& imu, double dt_s) {
  Entry e;
  for (int i = 0; i < 3; ++i) {
    e.predict.acc[i] = imu.b_acc_mps2(i);
    e.predict.gyro[i] = imu.b_gyro_radps(i);
  }
  e.predict.dt_s = dt_s;
  append(e);
}

void StartReplay::recordTdoa(const TdoaMeasurement& z) {
  Entry e;
  e.is_tdoa = true;
  e.z = z;
  append(e);
}

Ekf StartReplay::restart(const Vec3& p0, const Vec3& v0, double pos_sigma_m, double vel_sigma_mps) const {
  // (F16g) the fix is the starting point of the run rather than a measurement: a wide prior on p and v at t_ref
  // (so that the window's TDoA, from which p₀ and v₀ came, count about once), uncorrelated with the other states
  Ekf f = base_;
  f.propagateCovariance();
  Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Zero();
  cov.topLeftCorner<3, 3>().diagonal().setConstant(pos_sigma_m * pos_sigma_m);
  cov.bottomRightCorner<3, 3>().diagonal().setConstant(vel_sigma_mps * vel_sigma_mps);
  f.resetPositionVelocity(p0, v0, cov);
  return f;
}

}  // namespace uwb
