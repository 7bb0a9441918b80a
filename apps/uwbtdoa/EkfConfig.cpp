/** @file EkfConfig.cpp */
#include "EkfConfig.h"

#include <stdexcept>

#include "uwb/core/Error.h"
#include "uwb/io/JsonFile.h"

namespace uwb::app {

/// Reads the keys of a JSON object into EkfParams (names as the struct fields); unknown keys are an error.
/// Every value is checked for its type (and integers for their range) before it is converted; errors name the
/// file and the key.
void applyEkfConfig(const nlohmann::json& j, const std::string& path, EkfParams& p) {
  const auto fail = [&](const std::string& key, const std::string& message) {
    throw InputError(SourceLocation{path, 0, 0, key}, message);
  };
  if (!j.is_object()) fail("", "expected a JSON object of EkfParams fields, got " + std::string(j.type_name()));
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    const nlohmann::json& value = it.value();
    try {
      const auto num = [&] { return jsonDouble(value, key); };
      const auto str = [&] { return jsonString(value, key); };
      const auto vec = [&] {
        if (!value.is_array() || value.size() != 3) throw std::invalid_argument("'" + key + "' must be [x, y, z]");
        return Eigen::Vector3d(jsonDouble(value[0], key + "[0]"), jsonDouble(value[1], key + "[1]"),
                               jsonDouble(value[2], key + "[2]"));
      };
      if (key == "acc_noise_mps2_sqrthz") p.acc_noise_mps2_sqrthz = num();
      else if (key == "lateral_acc_noise_mps2_sqrthz") p.lateral_acc_noise_mps2_sqrthz = num();
      else if (key == "gyro_noise_radps_sqrthz") p.gyro_noise_radps_sqrthz = num();
      else if (key == "acc_bias_rw_mps3_sqrthz") p.acc_bias_rw_mps3_sqrthz = num();
      else if (key == "gyro_bias_rw_radps2_sqrthz") p.gyro_bias_rw_radps2_sqrthz = num();
      else if (key == "pos_noise_m_sqrts") p.pos_noise_m_sqrts = num();
      else if (key == "cv_acc_noise_mps2_sqrthz") p.cv_acc_noise_mps2_sqrthz = num();
      else if (key == "ca_jerk_noise_mps3_sqrthz") p.ca_jerk_noise_mps3_sqrthz = num();
      else if (key == "accel_model") p.accel_model = parseAccelModel(str());
      else if (key == "ground_accel_model") p.ground_accel_model = parseAccelModel(str());
      else if (key == "takeoff_acc_bias_sigma_mps2") p.takeoff_acc_bias_sigma_mps2 = num();
      else if (key == "process_model") p.process_model = parseProcessModel(str());
      else if (key == "init_pos_sigma_m") p.init_pos_sigma_m = num();
      else if (key == "init_vel_sigma_mps") p.init_vel_sigma_mps = num();
      else if (key == "init_att_sigma_rad") p.init_att_sigma_rad = num();
      else if (key == "init_yaw_sigma_rad") p.init_yaw_sigma_rad = num();
      else if (key == "init_acc_bias_sigma_mps2") p.init_acc_bias_sigma_mps2 = num();
      else if (key == "init_gyro_bias_sigma_radps") p.init_gyro_bias_sigma_radps = num();
      else if (key == "b_t_tag") p.b_t_tag = vec();
      else if (key == "tdoa_sigma_m") p.tdoa_sigma_m = num();
      else if (key == "anchor_sigma_m") p.anchor_sigma_m = num();
      else if (key == "gate_sigma") p.gate_sigma = num();
      else if (key == "robust_loss") p.robust_loss = parseRobustLoss(str());
      else if (key == "robust_k") p.robust_k = num();
      else if (key == "robust_iterations") p.robust_iterations = jsonInt(value, key, 1, kMaxRobustIterations);
      else if (key == "max_lost_s") p.max_lost_s = num();
      else if (key == "max_predict_dt_s") p.max_predict_dt_s = num();
      else if (key == "cov_period_s") p.cov_period_s = num();
      else if (key == "max_gap_s") p.max_gap_s = num();
      else if (key == "ground_phase") p.ground_phase = parseGroundPhase(str());
      else if (key == "takeoff_climb_mps") p.takeoff_climb_mps = num();
      else if (key == "takeoff_acc_mps2") p.takeoff_acc_mps2 = num();
      else if (key == "landing_height_m") p.landing_height_m = num();
      else if (key == "landing_hold_s") p.landing_hold_s = num();
      else if (key == "acquisition_s") p.acquisition_s = num();
      else if (key == "acquisition_tdoa_sigma_m") p.acquisition_tdoa_sigma_m = num();
      else if (key == "start_w_p_b") {
        p.start_w_p_b = vec();
        p.has_start_position = true;
      } else if (key == "ground_z_m") p.ground_z_m = num();
      else if (key == "fuse_tof") p.fuse_tof = jsonBool(value, key);
      else if (key == "tof_sigma_m") p.tof_sigma_m = num();
      else if (key == "tof_offset_m") p.tof_offset_m = num();
      else if (key == "floor_z_m") p.floor_z_m = num();
      else if (key == "tof_max_range_m") p.tof_max_range_m = num();
      else if (key == "tof_gate_sigma") p.tof_gate_sigma = num();
      else throw std::invalid_argument("unknown key '" + key + "' (keys are the EkfParams field names)");
    } catch (const std::invalid_argument& e) {
      fail(key, e.what());
    }
  }
}

}  // namespace uwb::app
