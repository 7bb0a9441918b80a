/** @file LocalizationJson.cpp
 *  @brief The JSON of a localization run's summary, error statistics and checks.
 */
#include "uwb/eval/LocalizationJson.h"

#include <cmath>

namespace uwb {

namespace {

using nlohmann::json;

json vecJson(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

json sensorRangeJson(const SensorRangeReport& report) {
  const auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  const auto one = [&](const SensorRangeCount& c) {
    return json{{"n", c.n}, {"limit", num(c.limit)}, {"first_t_s", c.n ? num(c.first_t_s) : json(nullptr)},
                {"worst", c.n ? num(c.worst) : json(nullptr)}};
  };
  return {{"gyro", one(report.gyro)}, {"acc", one(report.acc)}, {"tdoa", one(report.tdoa)}};
}

json localizerSummaryJson(const LocalizerSummary& s, const EkfParams& params) {
  json j;
  j["process_model"] = toString(s.process_model);
  j["bias_guard_mean_weight"] = s.bias_guard_mean_weight;
  j["bias_guard_final_weight"] = s.bias_guard_final_weight;
  j["n_tdoa"] = s.n_tdoa_total;
  j["n_tdoa_used"] = s.n_tdoa_used;
  j["n_tdoa_rejected"] = s.n_tdoa_rejected;
  j["n_tdoa_downweighted"] = s.n_tdoa_downweighted;
  j["n_tdoa_start"] = s.n_tdoa_start;
  j["n_tdoa_used_at_rest"] = s.n_tdoa_used_at_rest;
  j["n_tdoa_before_imu"] = s.n_tdoa_before_imu;
  j["n_tdoa_out_of_order"] = s.n_tdoa_out_of_order;
  j["n_zero_velocity_updates"] = s.n_zero_velocity_updates;
  j["n_rest_gyro_updates"] = s.n_rest_gyro_updates;
  j["n_rest_gyro_widenings"] = s.n_rest_gyro_widenings;
  j["n_floor_updates"] = s.n_floor_updates;
  j["n_descent_bound_updates"] = s.n_descent_bound_updates;
  j["n_rest_periods"] = s.n_rest_periods;
  j["n_landing_fixes"] = s.n_landing_fixes;
  j["n_time_jumps"] = s.n_time_jumps;
  j["reacquisition_t_s"] = s.reacquisition_t_s;
  j["reacquired_t_s"] = s.reacquired_t_s;
  j["ready_t_s"] = s.ready_t_s;
  j["n_tdoa_degenerate"] = s.n_tdoa_degenerate;
  j["n_reacquisitions"] = s.n_reacquisitions;
  j["floor_doubted_s"] = s.floor_doubted_s;
  j["floor_doubted_max_height_m"] = s.floor_doubted_max_height_m;
  j["n_mode_overrules"] = s.n_mode_overrules;
  j["air_shake_rms_radps"] = s.air_shake_rms_radps;
  j["n_inconsistent_periods"] = s.n_inconsistent_periods;
  j["inconsistent_s"] = s.inconsistent_s;
  j["n_consistency_widenings"] = s.n_consistency_widenings;
  j["n_floor_checks"] = s.n_floor_checks;
  j["n_floor_refutations"] = s.n_floor_refutations;
  j["n_rejection_faults"] = s.n_rejection_faults;
  j["n_reverted_motion"] = s.n_reverted_motion;
  j["start_replayed"] = s.start_replayed;
  j["start_floor_refuted"] = s.start_floor_refuted;
  j["start_rms_residual_m"] = s.start_rms_residual_m;
  j["n_heading_alignments"] = s.n_heading_alignments;
  j["heading_alignment_t_s"] = s.heading_alignment_t_s;
  j["heading_alignment_change_rad"] = s.heading_alignment_change_rad;
  j["bias_level_m"] = s.bias_level_m;
  j["n_bias_level_windows"] = s.n_bias_level_windows;
  j["raw_bias_level_m"] = s.raw_bias_level_m;
  j["bias_model_training_level_m"] = params.bias_model_training_level_m;
  j["model_mean_level_m"] = s.model_mean_level_m;
  j["bias_model_training_mean_level_m"] = params.bias_model_training_mean_level_m;
  j["bias_model_mean_scale"] = s.bias_model_mean_scale;
  j["min_bias_model_mean_scale"] = s.min_bias_model_mean_scale;
  j["bias_model_level_variance_m2"] = s.bias_model_level_variance_m2;
  j["fuse_tof"] = params.fuse_tof;
  j["n_tof"] = s.n_tof_total;
  j["n_tof_used"] = s.n_tof_used;
  j["n_tof_rejected"] = s.n_tof_rejected;
  j["n_tof_invalid"] = s.n_tof_invalid;
  j["n_tof_tilted"] = s.n_tof_tilted;
  j["n_tof_not_ready"] = s.n_tof_not_ready;
  j["sensor_range"] = sensorRangeJson(s.sensor_range);
  j["started_in_motion"] = s.started_in_motion;
  j["ground_entered_t_s"] = s.ground_entered_t_s;
  j["ground_left_t_s"] = s.ground_left_t_s;
  j["takeoff_t_s"] = s.takeoff_t_s;
  j["landing_t_s"] = s.landing_t_s;
  j["start_position_m"] = vecJson(s.start_w_p_b);
  j["merge_notes"] = s.merge.notes();
  return j;
}

json positionErrorStatsJson(const PositionErrorStats& s) {
  return {{"n", s.n},
          {"rmse_m", s.rmse_m},
          {"rmse_x_m", s.rmse_axis_m.x()},
          {"rmse_y_m", s.rmse_axis_m.y()},
          {"rmse_z_m", s.rmse_axis_m.z()},
          {"mean_m", s.mean_m},
          {"p50_m", s.p50_m},
          {"p90_m", s.p90_m},
          {"p99_m", s.p99_m},
          {"max_m", s.max_m}};
}

json runDiagnosticsJson(const RunDiagnostics& d) {
  json j;
  const SurveyFitCheck& s = d.survey;
  j["survey_fit"] = !s.done ? json(nullptr)
                            : json{{"n", s.n},
                                   {"residual_rms_m", s.truncated_rms_m},
                                   {"gross_fraction", s.gross_fraction},
                                   {"inlier_rms_m", s.inlier_rms_m},
                                   {"start_rms_residual_m", s.start_rms_residual_m},
                                   {"misfit", s.misfit},
                                   {"outliers", s.outliers},
                                   {"mean_error_vs_truth_m", s.has_truth ? vecJson(s.mean_error_m) : json(nullptr)},
                                   {"frame_offset", s.frame_offset}};
  if (d.anchors.done) {
    json per = json::array();
    for (const AnchorOffset& o : d.anchors.anchors)
      per.push_back({{"id", o.id},
                     {"n", o.n},
                     {"offset_m", vecJson(o.offset_m)},
                     {"offset_norm_m", o.offset_m.norm()},
                     {"rms_before_m", o.rms_before_m},
                     {"rms_after_m", o.rms_after_m},
                     {"gain_m", o.gain_m()}});
    j["anchor_survey"] = {{"anchors", per},
                          {"named_anchor", d.anchors.named_id >= 0 ? json(d.anchors.named_id) : json(nullptr)},
                          {"named_offset_m", d.anchors.named_id >= 0 ? vecJson(d.anchors.named_offset_m) : json(nullptr)},
                          {"top_gain_m", d.anchors.top_gain_m},
                          {"gain_ratio", d.anchors.named_ratio}};
  } else {
    j["anchor_survey"] = nullptr;
  }
  j["clock_offset"] = !d.clock.done ? json(nullptr)
                                    : json{{"lags_s", d.clock.lags_s},
                                           {"residual_rms_m", d.clock.rms_m},
                                           {"best_lag_s", d.clock.best_lag_s},
                                           {"power_ratio", d.clock.power_ratio},
                                           {"offset_detected", d.clock.offset}};
  return j;
}

}  // namespace uwb
