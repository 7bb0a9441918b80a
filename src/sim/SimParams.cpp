/** @file SimParams.cpp */
#include "uwb/sim/SimParams.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace uwb::sim {

namespace {
void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("SimParams: " + what);
}
bool finiteNonNegative(double v) { return std::isfinite(v) && v >= 0.0; }
}  // namespace

void ImuParams::validate() const {
  require(std::isfinite(rate_hz) && rate_hz >= 10.0 && rate_hz <= 10000.0, "imu.rate_hz must be in [10, 10000]");
  require(finiteNonNegative(acc_noise_std_mps2) && finiteNonNegative(acc_bias_std_mps2) &&
              finiteNonNegative(acc_bias_rw_mps2_sqrt_s),
          "imu accelerometer magnitudes must be >= 0");
  require(finiteNonNegative(gyro_noise_std_rps) && finiteNonNegative(gyro_bias_std_rps) &&
              finiteNonNegative(gyro_bias_rw_rps_sqrt_s),
          "imu gyroscope magnitudes must be >= 0");
  require(finiteNonNegative(rest_acc_noise_std_mps2) && finiteNonNegative(rest_gyro_noise_std_rps),
          "imu rest noise magnitudes must be >= 0");
}

void PoseParams::validate() const {
  require(std::isfinite(rate_hz) && rate_hz >= 1.0 && rate_hz <= 5000.0, "pose.rate_hz must be in [1, 5000]");
  require(finiteNonNegative(position_quantum_m) && position_quantum_m <= 0.1, "pose.position_quantum_m must be in [0, 0.1]");
  require(finiteNonNegative(quat_quantum) && quat_quantum <= 0.1, "pose.quat_quantum must be in [0, 0.1]");
}

void TdoaScheduleParams::validate() const {
  require(std::isfinite(rate_hz) && rate_hz >= 1.0 && rate_hz <= 5000.0, "tdoa.rate_hz must be in [1, 5000]");
  require(std::isfinite(jitter_fraction) && jitter_fraction >= 0.0 && jitter_fraction < 1.0,
          "tdoa.jitter_fraction must be in [0, 1)");
}

void SimParams::validate() const {
  imu.validate();
  pose.validate();
  tdoa.validate();
  bias.validate();
  require(b_t_tag.allFinite() && b_t_tag.norm() < 1.0, "b_t_tag must be finite and shorter than 1 m");
  require(std::isfinite(rotor_drag_per_s) && rotor_drag_per_s >= 0.0 && rotor_drag_per_s < 10.0,
          "rotor_drag_per_s must be in [0, 10) 1/s");
}

SimParams SimParams::noiseFree() {
  SimParams p;
  p.imu.acc_noise_std_mps2 = 0.0;
  p.imu.acc_bias_std_mps2 = 0.0;
  p.imu.acc_bias_rw_mps2_sqrt_s = 0.0;
  p.imu.gyro_noise_std_rps = 0.0;
  p.imu.rest_acc_noise_std_mps2 = 0.0;
  p.imu.rest_gyro_noise_std_rps = 0.0;
  p.imu.gyro_bias_std_rps = 0.0;
  p.imu.gyro_bias_rw_rps_sqrt_s = 0.0;
  p.pose.position_quantum_m = 0.0;
  p.pose.quat_quantum = 0.0;
  p.bias.enabled = false;
  p.rotor_drag_per_s = 0.0;  // the vehicle of the filter's thrust model (F3)
  return p;
}

}  // namespace uwb::sim
