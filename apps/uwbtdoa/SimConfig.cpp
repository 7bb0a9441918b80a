/** @file SimConfig.cpp */
#include "SimConfig.h"

#include <map>
#include <stdexcept>
#include <variant>

#include "uwb/core/Error.h"
#include "uwb/core/Strings.h"
#include "uwb/io/JsonFile.h"

namespace uwb::app {

using sim::SimParams;
using sim::TrajectoryParams;

namespace {

using Field = std::variant<double*, int*, bool*>;

void applyObject(const nlohmann::json& j, const std::string& section, const std::map<std::string, Field>& fields) {
  if (!j.is_object()) throw ConfigKeyError(section, "'" + section + "' must be an object");
  for (auto member = j.begin(); member != j.end(); ++member) {
    const std::string& key = member.key();
    const nlohmann::json& value = member.value();
    const std::string full = section + "." + key;
    const auto it = fields.find(key);
    if (it == fields.end()) {
      std::string known;
      for (const auto& field : fields) uwb::appendToList(&known, field.first);
      throw ConfigKeyError(full, "unknown key '" + full + "' (known: " + known + ")");
    }
    try {
      if (auto* d = std::get_if<double*>(&it->second)) {
        **d = jsonDouble(value, full);
      } else if (auto* i = std::get_if<int*>(&it->second)) {
        **i = jsonInt(value, full, 0, kMaxSimConfigInteger);
      } else if (auto* b = std::get_if<bool*>(&it->second)) {
        **b = jsonBool(value, full);
      }
    } catch (const std::invalid_argument& e) {
      throw ConfigKeyError(full, e.what());
    }
  }
}

}  // namespace

void applySimConfig(const nlohmann::json& j, SimParams* sp, TrajectoryParams* tp) {
  if (!j.is_object()) throw ConfigKeyError("", std::string("config must be a JSON object, got ") + j.type_name());
  for (auto member = j.begin(); member != j.end(); ++member) {
    const std::string& key = member.key();
    const nlohmann::json& value = member.value();
    if (key == "trajectory") {
      applyObject(value, key,
                  {{"ground_before_s", &tp->ground_before_s}, {"ground_after_s", &tp->ground_after_s},
                   {"takeoff_s", &tp->takeoff_s}, {"landing_s", &tp->landing_s},
                   {"speed_ramp_s", &tp->speed_ramp_s}, {"ground_z_m", &tp->ground_z_m},
                   {"radius_m", &tp->radius_m}, {"height_m", &tp->height_m}, {"omega_rps", &tp->omega_rps},
                   {"sine_amplitude_m", &tp->sine_amplitude_m}, {"sine_omega_ratio", &tp->sine_omega_ratio},
                   {"figure8_half_length_m", &tp->figure8_half_length_m},
                   {"figure8_half_width_m", &tp->figure8_half_width_m}, {"figure8_omega_rps", &tp->figure8_omega_rps},
                   {"zigzag_half_x_m", &tp->zigzag_half_x_m}, {"zigzag_half_y_m", &tp->zigzag_half_y_m},
                   {"zigzag_z_min_m", &tp->zigzag_z_min_m}, {"zigzag_z_max_m", &tp->zigzag_z_max_m},
                   {"zigzag_speed_mps", &tp->zigzag_speed_mps}, {"zigzag_sweep_ratio", &tp->zigzag_sweep_ratio},
                   {"yaw0_rad", &tp->yaw0_rad}, {"yaw_rate_rps", &tp->yaw_rate_rps},
                   {"center_x_m", &tp->w_center_xy.x()}, {"center_y_m", &tp->w_center_xy.y()}});
    } else if (key == "imu") {
      auto& p = sp->imu;
      applyObject(value, key,
                  {{"rate_hz", &p.rate_hz}, {"acc_noise_std_mps2", &p.acc_noise_std_mps2},
                   {"acc_bias_std_mps2", &p.acc_bias_std_mps2}, {"acc_bias_rw_mps2_sqrt_s", &p.acc_bias_rw_mps2_sqrt_s},
                   {"gyro_noise_std_rps", &p.gyro_noise_std_rps}, {"gyro_bias_std_rps", &p.gyro_bias_std_rps},
                   {"gyro_bias_rw_rps_sqrt_s", &p.gyro_bias_rw_rps_sqrt_s}});
    } else if (key == "pose") {
      auto& p = sp->pose;
      applyObject(value, key,
                  {{"rate_hz", &p.rate_hz}, {"position_quantum_m", &p.position_quantum_m},
                   {"quat_quantum", &p.quat_quantum}});
    } else if (key == "tdoa") {
      auto& p = sp->tdoa;
      applyObject(value, key, {{"rate_hz", &p.rate_hz}, {"jitter_fraction", &p.jitter_fraction}, {"tdoa3", &p.tdoa3}});
    } else if (key == "bias") {
      auto& p = sp->bias;
      applyObject(value, key,
                  {{"enabled", &p.enabled}, {"antenna_rms_m", &p.antenna_rms_m}, {"antenna_degree", &p.antenna_degree},
                   {"anchor_pattern_rms_m", &p.anchor_pattern_rms_m}, {"anchor_offset_std_m", &p.anchor_offset_std_m},
                   {"nlos_bias_m", &p.nlos_bias_m}, {"nlos_elevation_rad", &p.nlos_elevation_rad},
                   {"nlos_width_rad", &p.nlos_width_rad}, {"nlos_azimuth_gain", &p.nlos_azimuth_gain},
                   {"nlos_azimuth_rad", &p.nlos_azimuth_rad}, {"multipath_std_m", &p.multipath_std_m},
                   {"multipath_length_m", &p.multipath_length_m}, {"multipath_features", &p.multipath_features},
                   {"noise_std_m", &p.noise_std_m}, {"outlier_probability", &p.outlier_probability},
                   {"outlier_scale_m", &p.outlier_scale_m}, {"outlier_dof", &p.outlier_dof},
                   {"outlier_max_m", &p.outlier_max_m}, {"burst_probability", &p.burst_probability},
                   {"burst_length_s", &p.burst_length_s}, {"burst_scale_m", &p.burst_scale_m},
                   {"ground_effect", &p.ground_effect},
                   {"ground_low_anchor_z_m", &p.ground_low_anchor_z_m}, {"ground_low_min_m", &p.ground_low_min_m},
                   {"ground_low_max_m", &p.ground_low_max_m}, {"ground_high_abs_m", &p.ground_high_abs_m},
                   {"ground_noise_std_m", &p.ground_noise_std_m},
                   {"ground_blend_height_m", &p.ground_blend_height_m}});
    } else if (key == "b_t_tag") {
      if (!value.is_array() || value.size() != 3) throw ConfigKeyError(key, "'b_t_tag' must be [x, y, z]");
      try {
        for (int i = 0; i < 3; ++i) sp->b_t_tag[i] = jsonDouble(value.at(static_cast<std::size_t>(i)), "b_t_tag");
      } catch (const std::invalid_argument& e) {
        throw ConfigKeyError(key, e.what());
      }
    } else if (key == "rotor_drag_per_s") {
      try {
        sp->rotor_drag_per_s = jsonDouble(value, "rotor_drag_per_s");
      } catch (const std::invalid_argument& e) {
        throw ConfigKeyError(key, e.what());
      }
    } else {
      throw ConfigKeyError(key, "unknown section '" + key +
                                    "' (known: trajectory, imu, pose, tdoa, bias, b_t_tag, rotor_drag_per_s)");
    }
  }
}

void applySimConfigFile(const std::string& path, SimParams* sp, TrajectoryParams* tp) {
  const nlohmann::json j = readJsonFile(path, "config file");
  if (!j.is_object()) {
    throw InputError(SourceLocation{path, 0, 0, ""},
                          std::string("config must be a JSON object, got ") + j.type_name());
  }
  try {
    applySimConfig(j, sp, tp);
    // the ranges are the parameters' own (SimParams, TrajectoryParams::validate), checked here so that an error names
    // the file and the section it came from
    const auto check = [](const char* section, const auto& params) {
      try {
        params.validate();
      } catch (const std::invalid_argument& e) {
        throw ConfigKeyError(section, e.what());
      }
    };
    check("imu", sp->imu);
    check("pose", sp->pose);
    check("tdoa", sp->tdoa);
    check("bias", sp->bias);
    check("trajectory", *tp);
    check("", *sp);  // b_t_tag, rotor_drag_per_s
  } catch (const ConfigKeyError& e) {
    throw InputError(SourceLocation{path, 0, 0, e.key}, e.what());
  }
}

}  // namespace uwb::app
