/** @file cmd_localize.cpp
 *  @brief `uwbtdoa localize FLIGHT.csv --anchors SURVEY.txt [--out TRAJ.csv] [--json] [--config FILE.json] ...`:
 *         runs the localization filter (IMU-driven ESKF, or TDoA-only without IMU), writes the trajectory and
 *         prints the position RMSE against the flight's ground truth.
 */
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <deque>
#include <ctime>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "Command.h"
#include "uwb/core/Error.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/eval/Localization.h"
#include "uwb/eval/LocalizationJson.h"
#include "uwb/eval/RunDiagnostics.h"
#include "uwb/filter/EkfParamRegistry.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/JsonFile.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/io/UtilCsv.h"
#include "FilterOptions.h"
#include "Report.h"
#include "InputGuards.h"

namespace {

using nlohmann::json;

struct LocalizeArgs {
  std::string flight, anchors, out, plot;
  std::string format = "csv";  ///< --format: the trajectory file's format (csv, or tum for evo)
  bool json_out = false, tdoa_only = false, no_ground_detect = false;
  bool no_diagnostics = false, fix_survey = false;
  double output_period = 0.01;
  std::vector<double> window;  ///< --window T0,T1: localize the part of the log between these stamps
  uwb::app::FilterOptionArgs filter;  ///< --config, --bias-model, one flag per filter parameter
};

/// The log between the stamps of --window (every stream, as a log started at T0 and stopped at T1 would hold it:
/// io/FlightWindow.h); the whole log without the option.
uwb::Flight windowed(uwb::Flight flight, const std::vector<double>& window, const std::string& path) {
  if (window.empty()) return flight;
  const double t0 = window.at(0), t1 = window.at(1);
  const auto [first, last] = flight.timeSpan();
  uwb::Flight cut;
  try {
    cut = uwb::sliceFlight(flight, t0, t1);
  } catch (const std::invalid_argument& e) {
    throw uwb::InputError(fmt::format("--window T0,T1: {}", e.what()));
  }
  if (cut.tdoa.empty()) {
    throw uwb::InputError(fmt::format("--window {},{} holds no TDoA of {} (its streams span {:.3f} to {:.3f} s)", t0,
                                      t1, path, first, last));
  }
  return cut;
}

/// A run that never found a position has nothing to report (an RMSE over zero samples would read 0.000 m): an
/// error that says why, from what the input shows.
void requirePositionFound(const uwb::LocalizationRun& run, const uwb::Flight& flight, const uwb::AnchorSurvey& survey,
                          const std::string& path) {
  if (std::isfinite(run.summary.ready_t_s) && !run.trajectory.empty()) return;
  const std::size_t n = flight.tdoa.size();
  const double span_s = n > 1 ? flight.tdoa.back().t_s - flight.tdoa.front().t_s : 0.0;
  const uwb::SurveyGeometry g = uwb::surveyGeometry(survey);
  std::string why;
  if (n > 1 && span_s == 0.0) {
    why = fmt::format("all {} TDoA have the same time stamp (t = {:g} s)", n, flight.tdoa.front().t_s);
  } else if (g.principal_std_m.x() > uwb::kMaxAnchorSpread_m) {
    why = fmt::format("the anchors spread over {:.3g} m (principal std): the survey is not in metres or not this "
                      "arena's", g.principal_std_m.x());
  } else if (n < 50 || span_s < 1.0) {
    why = fmt::format("only {} TDoA over {:.3g} s: too few for a first fix", n, span_s);
  } else {
    why = fmt::format("no position fitted the {} TDoA over {:.3g} s ({} rejected by the gate): is the survey this "
                      "flight's?", n, span_s, run.summary.n_tdoa_rejected);
  }
  throw uwb::InputError(fmt::format("no position found in {}: {}; nothing written", path, why));
}

/// No non-finite estimate is written or summarised: an error naming how many and the first.
void requireFiniteEstimates(const uwb::Trajectory& trajectory, const std::string& path) {
  std::size_t bad = 0;
  double first_t = 0.0;
  for (const uwb::TrajectorySample& s : trajectory) {
    const bool finite = std::isfinite(s.t_s) && s.w_p_b.allFinite() && s.sigma_p_m.allFinite() &&
                        s.w_v_b.allFinite() && s.w_q_b.coeffs().allFinite();
    if (!finite && bad++ == 0) first_t = s.t_s;
  }
  if (bad > 0) {
    throw std::runtime_error(fmt::format("the estimate of {} diverged: {} of {} trajectory samples are not finite "
                                         "(first at t = {:.3f} s); nothing written. Check the bias model and the "
                                         "sensor values",
                                         path, bad, trajectory.size(), first_t));
  }
}

/// Largest --output-period [s]: one sample a minute still draws a trajectory.
constexpr double kMaxOutputPeriod_s = 60.0;

/// What the run reads: the filter parameters and bias model, the survey and the flight (windowed).
struct LocalizeInputs {
  uwb::EkfParams params;
  bool process_model_given = false, start_flag = false;
  uwb::BiasPredictor bias;
  uwb::AnchorSurvey survey;
  uwb::ReadReport read_report;
  uwb::Flight flight;
  bool use_imu = false;  ///< the IMU process model was asked for (or is the default) and --tdoa-only is off
};

/// Outputs first: a run of minutes must not end in "cannot write".
void checkOutputs(const LocalizeArgs& a) {
  const std::vector<std::string> inputs{a.flight, a.anchors, a.filter.config, a.filter.bias_model};
  if (!a.out.empty()) uwb::checkOutputFile(a.out, "trajectory file", inputs);
  if (!a.plot.empty()) uwb::checkOutputFile(a.plot, "plot file", inputs);
  uwb::app::checkPeriod(a.output_period, "--output-period", kMaxOutputPeriod_s);
}

/// Stream-rate issues of the flight; an IMU that the run ignores only warrants a warning.
void checkRates(const uwb::Flight& flight, bool use_imu, uwb::app::Warnings& warnings) {
  std::vector<uwb::InputIssue> issues = uwb::checkStreamRates(flight);
  for (uwb::InputIssue& i : issues) {
    const bool imu_field = i.where.field == "t_acc" || i.where.field == "t_gyro";
    if (imu_field && !use_imu) i.severity = uwb::IssueSeverity::kWarning;
  }
  warnings.addIssues(issues);
}

LocalizeInputs loadInputs(const LocalizeArgs& a, uwb::app::Warnings& warnings) {
  LocalizeInputs in;
  uwb::app::FilterSetup setup = uwb::app::buildFilterParams(a.filter);
  in.params = setup.params;
  in.process_model_given = setup.process_model_given;
  in.start_flag = setup.start_flag;
  if (a.no_ground_detect) in.params.ground_phase = uwb::GroundPhase::kNone;
  in.params.validate();
  in.bias = uwb::app::loadBiasPredictor(a.filter, &in.params);

  in.survey = uwb::readAnchorSurvey(a.anchors);
  warnings.addIssues(uwb::checkSurveyGeometry(in.survey));
  if (in.params.has_start_position)
    uwb::app::checkNearAnchors(in.params.start_w_p_b, in.survey,
                               in.start_flag ? "--start" : a.filter.config + " (start_w_p_b)");
  uwb::FlightReadOptions read_opt;
  read_opt.required = {uwb::Stream::kTdoa};
  read_opt.survey = &in.survey;
  in.flight = windowed(uwb::readFlightCsv(a.flight, read_opt, &in.read_report), a.window, a.flight);
  in.use_imu = in.params.process_model == uwb::ProcessModel::kImu && !a.tdoa_only;
  if (in.use_imu && in.process_model_given && !in.flight.hasImu()) {
    throw uwb::InputError(uwb::SourceLocation{a.flight, 1, 0, "t_acc"},
                          "process model 'imu' was asked for but the flight has no IMU streams (acc and gyro); use "
                          "--process-model cv or ca, or leave it out for the TDoA-only default");
  }
  checkRates(in.flight, in.use_imu, warnings);
  return in;
}

/// The run reported (with --fix-survey, that of the corrected survey), its checks and its timing.
struct LocalizeResult {
  uwb::LocalizationRun run;
  std::optional<uwb::RunDiagnostics> diag;
  std::vector<std::string> notes;  ///< expected behaviour worth stating (warnings are for doubtful input)
  double cpu_s = 0.0, wall_s = 0.0;
  double rmse_before_fix = std::numeric_limits<double>::quiet_NaN();  ///< --fix-survey: airborne RMSE before it
};

LocalizeResult runFilter(const LocalizeArgs& a, const LocalizeInputs& in, uwb::app::Warnings& warnings) {
  uwb::LocalizationOptions opt;
  opt.params = in.params;
  opt.output_period_s = a.output_period;
  opt.tdoa_only = a.tdoa_only;
  LocalizeResult res;
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();  // process CPU time: the filter runs on one thread
  res.run = uwb::localizeFlight(in.flight, in.survey, opt, in.bias);
  res.cpu_s = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  requirePositionFound(res.run, in.flight, in.survey, a.flight);  // before the checks below, which need an estimate
  requireFiniteEstimates(res.run.trajectory, a.flight);
  // the "wrong but plausible" checks: survey fit, one anchor mis-surveyed, TDoA/IMU clock offset (re-runs)
  std::optional<uwb::LocalizationRun> fixed_run;
  if (!a.no_diagnostics) {
    res.diag = uwb::diagnoseRun(in.flight, in.survey, opt, res.run, in.bias);
    for (const std::string& w : res.diag->warnings()) warnings.add(w);
    if (a.fix_survey && res.diag->anchors.named_id >= 0)
      fixed_run = uwb::localizeFlight(in.flight, uwb::correctedSurvey(in.survey, res.diag->anchors), opt, in.bias);
  }
  if (in.use_imu && !in.flight.hasImu() && res.run.summary.process_model != uwb::ProcessModel::kImu) {
    res.notes.push_back(std::string("the flight has no IMU: the TDoA-only '") +
                        uwb::toString(res.run.summary.process_model) + "' model ran (the default without IMU)");
  }
  if (fixed_run) {
    if (res.run.metrics && res.run.metrics->airborne.n) res.rmse_before_fix = res.run.metrics->airborne.rmse_m;
    res.run = std::move(*fixed_run);
  }
  requireFiniteEstimates(res.run.trajectory, a.flight);  // also the re-run of --fix-survey
  if (res.diag && a.fix_survey && res.diag->anchors.named_id >= 0) {
    res.notes.push_back("--fix-survey: anchor " + std::to_string(res.diag->anchors.named_id) +
                        " moved by its fitted offset; the results are those of the corrected survey");
  }
  return res;
}

/// Warnings from the run's summary: position lost and found again, sensor-time jumps, values out of range.
void addSummaryWarnings(const uwb::LocalizerSummary& s, uwb::app::Warnings& warnings) {
  // the estimate lost the TDoA or diverged and was found again (docs/math/filter.md F16): the positions around
  // these times are not to be trusted
  for (std::size_t k = 0; k < s.reacquisition_t_s.size(); ++k) {
    const double t_lost = s.reacquisition_t_s[k];
    const std::string found = k < s.reacquired_t_s.size()
                                  ? ", found again at t = " + fmt::format("{:.2f}", s.reacquired_t_s[k]) + " s (" +
                                        fmt::format("{:.1f}", s.reacquired_t_s[k] - t_lost) +
                                        " s predicted without TDoA: see the position std)"
                                  : ", not found again before the end";
    warnings.add("position lost at t = " + fmt::format("{:.2f}", t_lost) + " s" + found +
                 " (TDoA inconsistent with the estimate or missing, divergence, or a sensor-time jump)");
  }
  if (s.n_time_jumps > 0)
    warnings.add(std::to_string(s.n_time_jumps) + " sensor-time gap(s) or backward jump(s): the IMU was not integrated "
                 "across them");
  for (const std::string& w : uwb::sensorRangeWarnings(s.sensor_range)) warnings.add(w);  // (F31)
}

json localizeJson(const LocalizeArgs& a, const LocalizeInputs& in, const LocalizeResult& res,
                  const uwb::app::Warnings& warnings) {
  const uwb::LocalizationRun& run = res.run;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  json j = uwb::localizerSummaryJson(run.summary, in.params);  // eval/LocalizationJson.h, shared with Python
  j["flight"] = a.flight;
  j["window_s"] = a.window.empty() ? json(nullptr) : json(a.window);
  j["duration_s"] = run.duration_s;
  j["bias_model"] = a.filter.bias_model.empty() ? json(nullptr) : json(a.filter.bias_model);
  j["diagnostics"] = res.diag ? uwb::runDiagnosticsJson(*res.diag) : json(nullptr);
  if (res.diag && a.fix_survey && res.diag->anchors.named_id >= 0) {
    // the estimate with the named anchor moved by its fitted offset: the trajectory written and the RMSE below
    const uwb::Vec3& offset = res.diag->anchors.named_offset_m;
    j["fixed_survey"] = {{"anchor", res.diag->anchors.named_id},
                         {"offset_m", {offset.x(), offset.y(), offset.z()}},
                         {"rmse_airborne_before_m",
                          std::isfinite(res.rmse_before_fix) ? json(res.rmse_before_fix) : json(nullptr)}};
  }
  j["read_notes"] = in.read_report.notes;
  j["warnings"] = warnings.list();
  j["notes"] = res.notes;
  j["wall_time_s"] = res.wall_s;
  j["real_time_factor"] = res.wall_s > 0 ? run.duration_s / res.wall_s : nan;  // wall clock: slower on a loaded machine
  j["cpu_time_s"] = res.cpu_s;
  j["real_time_factor_cpu"] = res.cpu_s > 0 ? run.duration_s / res.cpu_s : nan;
  if (run.metrics) {
    const uwb::TrajectoryMetrics& m = *run.metrics;
    j["rmse_m"] = m.whole.n ? json(m.whole.rmse_m) : json(nullptr);
    j["rmse_airborne_m"] = m.airborne.n ? json(m.airborne.rmse_m) : json(nullptr);
    j["whole"] = uwb::positionErrorStatsJson(m.whole);
    j["airborne"] = uwb::positionErrorStatsJson(m.airborne);
    j["n_truth_glitches"] = run.n_truth_glitches;
  } else {
    j["rmse_m"] = nullptr;
    j["rmse_airborne_m"] = nullptr;
  }
  return j;
}

/// x, y, z against time with the ±2σ band and the ground truth (docs/math/filter.md F23); drawn to a temporary name
/// beside the target and renamed, so the PNG appears complete or not at all. The temporary names follow
/// writeFileAtomically's pattern: removed on SIGINT/SIGTERM, swept by a later run after a SIGKILL.
void drawPlot(const LocalizeArgs& a, const uwb::Trajectory& trajectory) {
  const std::filesystem::path png(a.plot);
  const std::filesystem::path tmp_traj = uwb::temporaryPathBeside(a.plot, ".trajectory.csv");
  const std::filesystem::path tmp_png = uwb::temporaryPathBeside(a.plot, ".png");
  const uwb::TemporaryFileGuard traj_guard(tmp_traj.string()), png_guard(tmp_png.string());
  const auto cleanup = [&] {
    std::error_code ec;
    std::filesystem::remove(tmp_traj, ec);
    std::filesystem::remove(tmp_png, ec);
  };
  try {
    uwb::writeTrajectoryCsv(trajectory, tmp_traj.string());
    uwb::app::runPlots({"position", tmp_traj.string(), a.flight, tmp_png.string()});
    uwb::checkOutputFile(a.plot, "plot file");  // still a regular file (or absent) and no input
    std::filesystem::rename(tmp_png, png);
  } catch (...) {
    cleanup();
    throw;
  }
  cleanup();
}

void printErrorStats(const char* name, const uwb::PositionErrorStats& st) {
  if (st.n == 0) {  // never an RMSE over zero samples
    std::printf("%-9s n=%6zu  no estimate to compare%s\n", name, st.n,
                std::string(name) == "airborne" ? " (the ground truth never leaves the floor)" : "");
    return;
  }
  std::printf("%-9s n=%6zu  RMSE 3D %.3f m  (x %.3f, y %.3f, z %.3f)  p50 %.3f  p90 %.3f  p99 %.3f m\n", name, st.n,
              st.rmse_m, st.rmse_axis_m.x(), st.rmse_axis_m.y(), st.rmse_axis_m.z(), st.p50_m, st.p90_m, st.p99_m);
}

void printLocalizeText(const LocalizeArgs& a, const uwb::EkfParams& params, const LocalizeResult& res) {
  const uwb::LocalizationRun& run = res.run;
  const uwb::LocalizerSummary& s = run.summary;
  std::cout << "flight " << a.flight << ": " << run.duration_s << " s, model " << uwb::toString(s.process_model)
            << ", TDoA used " << s.n_tdoa_used << " (at rest " << s.n_tdoa_used_at_rest << ") / rejected "
            << s.n_tdoa_rejected << " / start-up " << s.n_tdoa_start << " of " << s.n_tdoa_total << "\n";
  if (params.fuse_tof) {
    std::cout << "ToF used " << s.n_tof_used << " / rejected " << s.n_tof_rejected << " / invalid " << s.n_tof_invalid
              << " / tilted " << s.n_tof_tilted << " / before the start " << s.n_tof_not_ready << " of "
              << s.n_tof_total << (s.n_tof_total == 0 ? " (the flight has no ToF stream)" : "") << "\n";
  }
  if (s.started_in_motion) std::cout << "the log starts with the body in motion (in the air or carried)\n";
  if (!std::isnan(s.ready_t_s)) std::cout << "position found at " << s.ready_t_s << " s\n";
  if (!std::isnan(s.takeoff_t_s)) std::cout << "left rest at " << s.takeoff_t_s << " s\n";
  if (!std::isnan(s.landing_t_s)) std::cout << "last came to rest after moving (landed) at " << s.landing_t_s << " s\n";
  if (!std::isnan(s.bias_level_m)) {
    // (F23c) the reported band is widened when the flight's level exceeds the reference
    const double widen = std::max(1.0, s.bias_level_m / params.output_bias_level_m);
    std::printf("TDoA bias level measured in flight %.3f m (reference %.2f m; reported bias std x%.2f)\n",
                s.bias_level_m, params.output_bias_level_m, widen);
  }
  for (const std::string& n : s.merge.notes()) std::cout << "note: " << n << "\n";
  for (const std::string& n : res.notes) std::cout << "note: " << n << "\n";
  if (run.metrics) {
    printErrorStats("whole", run.metrics->whole);
    printErrorStats("airborne", run.metrics->airborne);
  } else {
    std::cout << "no ground truth in the flight: no RMSE\n";
  }
  if (!a.out.empty()) std::cout << "trajectory written to " << a.out << "\n";
}

void runLocalize(const LocalizeArgs& a) {
  uwb::app::Warnings warnings;
  checkOutputs(a);
  const LocalizeInputs in = loadInputs(a, warnings);
  const LocalizeResult res = runFilter(a, in, warnings);
  addSummaryWarnings(res.run.summary, warnings);
  // The JSON text is made before the trajectory file appears, so a failure here leaves no output behind.
  const std::string json_text = uwb::app::dumpJson(localizeJson(a, in, res, warnings));
  if (!a.out.empty()) {
    if (a.format == "tum")
      uwb::writeTrajectoryTum(res.run.trajectory, a.out);
    else
      uwb::writeTrajectoryCsv(res.run.trajectory, a.out);
  }
  if (!a.plot.empty()) drawPlot(a, res.run.trajectory);
  if (a.json_out) {
    std::cout << json_text << '\n';
    return;
  }
  printLocalizeText(a, in.params, res);
}

const bool kRegistered = uwb::app::registerCommand(
    {"localize", "Localize a flight with the TDoA filter; write the trajectory, print RMSE against ground truth",
     [](CLI::App& sub) {
       auto a = std::make_shared<LocalizeArgs>();
       sub.add_option("flight", a->flight, "Flight CSV (UTIL layout)")->required();
       sub.add_option("--anchors", a->anchors, "Anchor survey (UTIL survey text)")->required();
       sub.add_option("--out", a->out, "Write the estimated trajectory here (CSV, or TUM with --format tum)");
       sub.add_option("--format", a->format,
                      "Trajectory file format: csv (pose, σ, velocity, IMU biases) or tum (timestamp x y z qx qy qz "
                      "qw, space-separated, for evo)")
           ->check(CLI::IsMember({"csv", "tum"}));
       sub.add_option("--plot", a->plot,
                      "Draw x, y, z against time with the ±2σ band and the ground truth to this PNG (python3)");
       sub.add_flag("--json", a->json_out, "Print one JSON object with the results");
       sub.add_flag("--tdoa-only", a->tdoa_only, "Ignore the IMU: constant-velocity model");
       sub.add_flag("--no-ground-detect", a->no_ground_detect,
                    "Use TDoA from the start (no take-off detection; = --ground-phase none)");
       uwb::app::addFilterOptions(sub, a->filter);
       sub.add_option("--output-period", a->output_period, "Trajectory sample spacing [s]");
       sub.add_option("--window", a->window,
                      "Localize only the part of the log from T0 to T1 [s] (every stream cut there, as a log started "
                      "at T0, e.g. in the air, and stopped at T1)")
           ->expected(2)
           ->delimiter(',')
           ->type_name("T0,T1");
       sub.add_flag("--no-diagnostics", a->no_diagnostics,
                    "Skip the checks after the run (survey fit, per-anchor survey; they re-run the filter once per "
                    "anchor)");
       sub.add_flag("--fix-survey", a->fix_survey,
                    "When the checks name a mis-surveyed anchor, re-run with it moved by its fitted offset and report "
                    "that run");
       sub.callback([a] { runLocalize(*a); });
     }});

}  // namespace
