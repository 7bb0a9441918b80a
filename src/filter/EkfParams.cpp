/** @file EkfParams.cpp
 *  @brief Validation, presets and enum names of the filter parameters.
 */
#include "uwb/filter/EkfParams.h"

#include <stdexcept>

#include "uwb/filter/EkfParamRegistry.h"

namespace uwb {

void EkfParams::validate() const {
  // every field's kind and range, from the one registry (EkfParamRegistry.cpp)
  validateEkfParamRanges(*this);
  // what a range cannot say
  if (antenna_bias_degree == 1)
    throw std::invalid_argument("EkfParams.antenna_bias_degree must be 0 (off) or in [2, 4]");
  flight_mode.validate();  // (F29) the supervisor's own checks, with the orderings of its bounds and heights
}

EkfParams EkfParams::crazyflieLike() {
  EkfParams p;
  p.accel_model = AccelModel::kThrustOnly;
  p.robust_loss = RobustLoss::kNone;
  p.robust_iterations = 1;
  p.tdoa_sigma_m = 0.15;  // Crazyflie measNoiseTdoa
  p.gate_sigma = 4.0;
  p.acc_noise_mps2_sqrthz = 0.5;
  p.lateral_acc_noise_mps2_sqrthz = 0.0;
  p.gyro_noise_radps_sqrthz = 0.01;
  p.acc_bias_rw_mps3_sqrthz = 0.0;
  p.gyro_bias_rw_radps2_sqrthz = 0.0;
  p.pos_noise_m_sqrts = 0.0;
  return p;
}

EkfParams EkfParams::tdoaOnly() {
  EkfParams p;
  p.process_model = ProcessModel::kConstantVelocity;
  p.ground_phase = GroundPhase::kNone;
  return p;
}

std::string toString(AccelModel m) { return m == AccelModel::kFull ? "full" : "thrust"; }
std::string toString(ProcessModel m) {
  switch (m) {
    case ProcessModel::kImu: return "imu";
    case ProcessModel::kConstantVelocity: return "cv";
    case ProcessModel::kConstantAcceleration: return "ca";
  }
  return "?";
}
std::string toString(RobustLoss l) {
  switch (l) {
    case RobustLoss::kNone: return "none";
    case RobustLoss::kHuber: return "huber";
    case RobustLoss::kCauchy: return "cauchy";
  }
  return "?";
}
std::string toString(GroundPhase g) { return g == GroundPhase::kNone ? "none" : "detect"; }

AccelModel parseAccelModel(const std::string& s) {
  if (s == "full") return AccelModel::kFull;
  if (s == "thrust") return AccelModel::kThrustOnly;
  throw std::invalid_argument("unknown accelerometer model '" + s + "' (full, thrust)");
}
ProcessModel parseProcessModel(const std::string& s) {
  if (s == "imu") return ProcessModel::kImu;
  if (s == "cv") return ProcessModel::kConstantVelocity;
  if (s == "ca") return ProcessModel::kConstantAcceleration;
  throw std::invalid_argument("unknown process model '" + s + "' (imu, cv, ca)");
}
RobustLoss parseRobustLoss(const std::string& s) {
  if (s == "none") return RobustLoss::kNone;
  if (s == "huber") return RobustLoss::kHuber;
  if (s == "cauchy") return RobustLoss::kCauchy;
  throw std::invalid_argument("unknown robust loss '" + s + "' (none, huber, cauchy)");
}
GroundPhase parseGroundPhase(const std::string& s) {
  if (s == "detect") return GroundPhase::kDetectTakeoff;
  if (s == "none") return GroundPhase::kNone;
  throw std::invalid_argument("unknown ground phase '" + s + "' (detect, none)");
}
std::string toString(BiasPoseUncertainty b) {
  switch (b) {
    case BiasPoseUncertainty::kVariance: return "variance";
    case BiasPoseUncertainty::kJacobian: return "jacobian";
    case BiasPoseUncertainty::kNone: break;
  }
  return "none";
}
BiasPoseUncertainty parseBiasPoseUncertainty(const std::string& s) {
  if (s == "none") return BiasPoseUncertainty::kNone;
  if (s == "variance") return BiasPoseUncertainty::kVariance;
  if (s == "jacobian") return BiasPoseUncertainty::kJacobian;
  throw std::invalid_argument("unknown bias-model pose uncertainty '" + s + "' (none, variance, jacobian)");
}

}  // namespace uwb
