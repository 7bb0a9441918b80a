/** @file Localization.cpp
 *  @brief Flight → filter → trajectory and metrics.
 */
#include "uwb/eval/Localization.h"

#include "uwb/io/PoseTrack.h"

namespace uwb {

SensorLog sensorLogFromFlight(const Flight& flight, MergeReport* report, bool with_tof) {
  SensorLog log;
  if (flight.hasImu()) {
    std::vector<TimedVec3> acc, gyro;
    acc.reserve(flight.acc.size());
    gyro.reserve(flight.gyro.size());
    for (const ImuSample& s : flight.acc) acc.push_back({s.t_s, s.b_value});
    for (const ImuSample& s : flight.gyro) gyro.push_back({s.t_s, s.b_value});
    log.imu = pairImuStreams(acc, gyro, report);
  }
  log.tdoa = flight.tdoa;
  if (with_tof) {
    log.tof.reserve(flight.tof.size());
    for (const ScalarSample& s : flight.tof) log.tof.push_back({s.t_s, s.value});
  }
  return log;
}

SensorLog replayLogFromFlight(const Flight& flight, MergeReport* report) {
  MergeReport pair_report;
  SensorLog log = sensorLogFromFlight(flight, &pair_report, /*with_tof=*/true);
  MergeReport clean_report = cleanSensorLog(log, EkfParams{}.max_gap_s);
  clean_report.n_imu_unpaired = pair_report.n_imu_unpaired;
  if (report) *report = clean_report;
  return log;
}

AnchorTable anchorTableFromSurvey(const AnchorSurvey& survey, double anchor_sigma_m) {
  AnchorTable table;
  for (const Anchor& a : survey.anchors) table.set(a.id, a.w_p, anchor_sigma_m);
  return table;
}

Trajectory toTrajectory(const std::vector<LocalizerEstimate>& estimates, bool imu_biases) {
  Trajectory out;
  out.reserve(estimates.size());
  for (const LocalizerEstimate& e : estimates) {
    TrajectorySample s;
    s.t_s = e.t_s;
    s.w_p_b = e.x.w_p_b;
    s.w_q_b = e.x.w_q_b;
    s.sigma_p_m = e.sigma_p_m;
    s.w_v_b = e.x.w_v_b;
    if (imu_biases) {
      s.b_acc_bias = e.x.b_acc_bias;
      s.b_gyro_bias = e.x.b_gyro_bias;
    }
    out.push_back(s);
  }
  return out;
}

LocalizationRun localizeFlight(const Flight& flight, const AnchorSurvey& survey, const LocalizationOptions& options,
                               const BiasPredictor& bias) {
  EkfParams params = options.params;
  if (options.tdoa_only && params.process_model == ProcessModel::kImu)
    params.process_model = ProcessModel::kConstantVelocity;
  MergeReport pair_report;
  SensorLog log = sensorLogFromFlight(flight, &pair_report, params.fuse_tof);
  const TdoaLocalizer localizer(params, anchorTableFromSurvey(survey, params.anchor_sigma_m), bias);
  LocalizerResult res = localizer.run(std::move(log), options.output_period_s);
  res.summary.merge.n_imu_unpaired = pair_report.n_imu_unpaired;
  LocalizationRun run;
  run.trajectory = toTrajectory(res.estimates, res.summary.process_model == ProcessModel::kImu);
  run.summary = res.summary;
  run.n_tdoa_used_at_rest.reserve(res.estimates.size());
  for (const LocalizerEstimate& e : res.estimates) run.n_tdoa_used_at_rest.push_back(e.n_tdoa_used_at_rest);
  run.duration_s = res.summary.end_t_s - res.summary.start_t_s;
  if (flight.hasGroundTruth()) {
    const PoseTrack track(flight);
    run.n_truth_glitches = track.glitches().size();
    run.metrics = computeTrajectoryMetrics(run.trajectory, track.samples(), options.metrics);
  }
  return run;
}

}  // namespace uwb
