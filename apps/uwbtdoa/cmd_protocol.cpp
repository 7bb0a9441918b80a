/** @file cmd_protocol.cpp
 *  @brief `uwbtdoa protocol`: the generalization protocol. Every real development flight localized whole and cut
 *         to start in the air (at 5, 10, 20 s) and to end before landing; simulated scenarios that real data cannot
 *         show (start in hover, long still hover, two take-offs, fast flight; several seeds, anchor layouts and
 *         bias fields); per-session medians for leave-one-session-out checks; per-axis σ coverage. Prints Markdown
 *         tables (or one JSON object with --json).
 */
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "Command.h"
#include "uwb/core/Error.h"
#include "uwb/eval/EstimateChecks.h"
#include "uwb/eval/FaultInjection.h"
#include "uwb/eval/RunDiagnostics.h"
#include "uwb/filter/EkfParamRegistry.h"
#include "uwb/eval/Localization.h"
#include "uwb/eval/ProtocolScenarios.h"
#include "uwb/eval/SignatureMatrix.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/io/UtilCsv.h"

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

struct ProtocolArgs {
  std::string data_dir;
  std::vector<double> cuts{5.0, 10.0, 20.0};
  std::vector<std::string> sets;
  bool json_out = false, no_real = false, no_sim = false, no_cuts = false, faults = false, checks = false,
       signatures = false;
  std::string only;
  int draws = 3;           ///< vibration draws per cell of the signature matrix
  std::string write_sims;  ///< folder for the simulated runs' flight CSV and survey (empty: none written)
  std::string write_cuts;  ///< folder for the real flights' mid-air cuts as flight CSV, with their survey
};

/// --data, else $UWBTDOA_DATA or the build-time default.
std::string dataDir(const ProtocolArgs& a) { return a.data_dir.empty() ? uwb::app::defaultDataDir() : a.data_dir; }

struct RealFlight {
  std::string name, session, path, survey;
};

std::vector<RealFlight> realFlights(const std::string& data_dir) {
  std::vector<RealFlight> out;
  const std::string pilot = data_dir + "/real/util-pilot";
  const std::string extract = data_dir + "/real/util-final-extract";
  for (int i = 1; i <= 12; ++i)
    out.push_back({"0425-traj" + std::to_string(i), "0425", pilot + "/0425/0425-traj" + std::to_string(i) + ".csv",
                   pilot + "/survey/anchor_0425_survey.txt"});
  // TDoA3 (the LPS mode of current firmware: random anchor pairs at a lower rate per pair), its own session so that
  // the TDoA2 development medians compare across versions
  out.push_back({"0425-traj13", "0425-tdoa3", pilot + "/0425/0425-traj13.csv", pilot + "/survey/anchor_0425_survey.txt"});
  for (int i : {1, 2, 11, 12})
    out.push_back({"0426-traj" + std::to_string(i), "0426", pilot + "/0426/0426-traj" + std::to_string(i) + ".csv",
                   pilot + "/survey/anchor_0426_survey.txt"});
  for (const char* trial : {"trial1", "trial2"})
    for (int j = 1; j <= 3; ++j) {
      const std::string n = std::string("const4-") + trial + "-tdoa2-traj" + std::to_string(j);
      out.push_back({n, "const4", extract + "/" + n + ".csv", extract + "/survey/anchor_const4_survey.txt"});
    }
  return out;
}

/// Applies a --set name=value override through the parameter registry (every EkfParams field, its range checked).
void applySet(const std::string& kv, uwb::EkfParams& p) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("--set: expected name=value, got '" + kv + "'");
  uwb::setEkfParamFromText(p, uwb::ekfParamInfo(kv.substr(0, eq)), kv.substr(eq + 1), "--set");
}

/// The development flights: the util-pilot TDoA2 sessions with IMU.
bool isDevSession(const std::string& session) { return session == "0425" || session == "0426"; }

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
double maxOf(const std::vector<double>& v) {
  double m = std::nan("");
  for (double x : v)
    if (std::isfinite(x)) m = std::isnan(m) ? x : std::max(m, x);
  return m;
}

struct Row {
  std::string name, session, kind;
  double t0 = 0.0, t1 = 0.0;
  double rmse_air = std::nan(""), rmse_ref = std::nan(""), max_err = std::nan(""), max_err_air = std::nan("");
  double early = std::nan(""), early_ref = std::nan("");  ///< RMSE 3–5 s after the log's start; the whole flight's
  double step = std::nan(""), zmin = std::nan(""), zmax = std::nan(""), settle = std::nan(""), err3 = std::nan("");
  double err_ground = std::nan("");
  uwb::Vec3 cov1 = uwb::Vec3::Constant(std::nan("")), cov2 = uwb::Vec3::Constant(std::nan(""));
  std::size_t n_cov = 0;  ///< airborne samples behind cov1, cov2
  double used_frac = std::nan("");
  bool violated = false;
  std::size_t reacq = 0;
  double bias_level = std::nan("");  ///< the flight's TDoA bias level measured in flight (filter.md F23c)
  /// The survey-fit check after the run (eval/RunDiagnostics.h) warned: on these clean flights, a false alarm
  bool survey_warning = false;
};

Row evaluateRun(const uwb::LocalizationRun& run, const std::string& name, const std::string& session,
                const std::string& kind, uwb::EstimateCheckParams cp, const uwb::Flight& flight,
                const uwb::AnchorSurvey& survey, const uwb::LocalizationOptions& opt) {
  if (!flight.tdoa.empty()) cp.t_start_s = flight.tdoa.front().t_s;
  Row r;
  uwb::RunDiagnosticParams survey_fit_only;  // no re-run: the residuals of this run
  survey_fit_only.anchor_survey = false;
  survey_fit_only.clock_offset = false;
  r.survey_warning = uwb::diagnoseRun(flight, survey, opt, run, {}, survey_fit_only).survey.misfit;
  r.name = name;
  r.session = session;
  r.kind = kind;
  r.reacq = run.summary.n_reacquisitions;
  r.bias_level = run.summary.bias_level_m;
  const std::size_t n_tdoa = run.summary.n_tdoa_total;
  r.used_frac = n_tdoa ? static_cast<double>(run.summary.n_tdoa_used + run.summary.n_tdoa_rejected +
                                             run.summary.n_tdoa_start) /
                             static_cast<double>(n_tdoa)
                       : std::nan("");
  if (!run.metrics) return r;
  const uwb::TrajectoryMetrics& m = *run.metrics;
  r.rmse_air = m.airborne.n ? m.airborne.rmse_m : std::nan("");
  r.max_err = m.whole.max_m;
  r.max_err_air = m.airborne.max_m;
  const uwb::EstimateChecks c = uwb::checkEstimate(run.trajectory, m, cp);
  r.step = c.max_airborne_step_m;
  r.zmin = c.min_z_on_ground_m;
  r.zmax = c.max_z_on_ground_m;
  r.err_ground = c.max_error_before_takeoff_m;
  r.settle = c.settle_time_s;
  r.err3 = c.max_error_after_3s_m;
  r.early = c.rmse_3_to_5s_m;
  r.cov1 = c.coverage_1sigma;
  r.cov2 = c.coverage_2sigma;
  r.n_cov = c.n_coverage;
  r.violated = c.floor_or_ceiling_violated;
  return r;
}

/// A table cell: scale · v with `decimals` digits after the point, or "–" when v is not finite.
std::string cell(double v, int decimals, double scale = 1.0) {
  if (!std::isfinite(v)) return "–";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", decimals, scale * v);
  return b;
}
std::string fmt3(double v) { return cell(v, 3); }
/// A figure for the JSON output: null when not finite.
json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
std::string fmt2(double v) { return cell(v, 2); }
std::string pct(double v) { return cell(v, 0, 100.0); }

/// A cut's start time as written in labels and file names: 10 → "10", 7.5 → "7.5".
std::string cutTime(double t0) {
  std::ostringstream os;
  os << t0;
  return os.str();
}

json rowJson(const Row& r) {
  return {{"name", r.name},
          {"session", r.session},
          {"kind", r.kind},
          {"t0_s", r.t0},
          {"t1_s", r.t1},
          {"rmse_airborne_m", num(r.rmse_air)},
          {"rmse_full_flight_same_window_m", num(r.rmse_ref)},
          {"max_error_m", num(r.max_err)},
          {"max_error_airborne_m", num(r.max_err_air)},
          {"max_error_before_takeoff_m", num(r.err_ground)},
          {"max_airborne_step_m", num(r.step)},
          {"min_z_on_ground_m", num(r.zmin)},
          {"max_z_on_ground_m", num(r.zmax)},
          {"settle_time_s", num(r.settle)},
          {"max_error_after_3s_m", num(r.err3)},
          {"rmse_3_to_5s_after_start_m", num(r.early)},
          {"rmse_3_to_5s_full_flight_same_window_m", num(r.early_ref)},
          {"coverage_1sigma_xyz", {num(r.cov1.x()), num(r.cov1.y()), num(r.cov1.z())}},
          {"coverage_2sigma_xyz", {num(r.cov2.x()), num(r.cov2.y()), num(r.cov2.z())}},
          {"tdoa_used_or_gated_fraction", num(r.used_frac)},
          {"floor_or_ceiling_violated", r.violated},
          {"n_reacquisitions", r.reacq},
          {"bias_level_m", num(r.bias_level)},
          {"survey_fit_warning", r.survey_warning}};
}

void printTable(const std::string& title, const std::vector<Row>& rows, bool cuts) {
  std::cout << "\n### " << title << "\n\n";
  if (cuts) {
    std::cout << "| flight | kind | window [s] | RMSE air [m] | full flight, same window [m] | RMSE 3–5 s after "
                 "start [m] | full flight, same 3–5 s [m] | max err after 3 s [m] | max step [m] | TDoA used+gated "
                 "[%] | reacq |\n"
                 "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows)
      std::cout << "| " << r.name << " | " << r.kind << " | " << fmt2(r.t0) << "–" << fmt2(r.t1) << " | "
                << fmt3(r.rmse_air) << " | " << fmt3(r.rmse_ref) << " | " << fmt3(r.early) << " | "
                << fmt3(r.early_ref) << " | " << fmt3(r.err3)
                << " | " << fmt3(r.step) << " | " << pct(r.used_frac) << " | " << r.reacq << " |\n";
    return;
  }
  std::cout << "| flight | RMSE air [m] | max err [m] | max err air [m] | max err on the ground before take-off [m] "
               "| max step air [m] | z on ground after flight [m] | 1σ cov x/y/z [%] | 2σ cov x/y/z [%] | TDoA "
               "used+gated [%] | reacq |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows)
    std::cout << "| " << r.name << " | " << fmt3(r.rmse_air) << " | " << fmt3(r.max_err) << " | "
              << fmt3(r.max_err_air) << " | " << fmt3(r.err_ground) << " | " << fmt3(r.step) << " | "
              << fmt2(r.zmin) << "…" << fmt2(r.zmax)
              << (r.violated ? " (!)" : "") << " | " << pct(r.cov1.x()) << "/" << pct(r.cov1.y()) << "/"
              << pct(r.cov1.z()) << " | " << pct(r.cov2.x()) << "/" << pct(r.cov2.y()) << "/" << pct(r.cov2.z())
              << " | " << pct(r.used_frac) << " | " << r.reacq << " |\n";
}

json summarize(const std::vector<Row>& rows, const std::string& label, bool print) {
  std::map<std::string, std::vector<const Row*>> by_session;
  for (const Row& r : rows) {
    by_session[r.session].push_back(&r);
    by_session["all"].push_back(&r);
    // the development flights: the util-pilot TDoA2 sessions with IMU
    if (isDevSession(r.session)) by_session["dev (0425+0426)"].push_back(&r);
  }
  json out = json::object();
  if (print)
    std::cout << "\n" << label << " — per session: median / worst airborne RMSE [m], worst max step [m], median 1σ "
              << "coverage x/y/z [%], median 2σ coverage x/y/z [%], the airborne samples pooled: 2σ coverage x/y/z [%], "
              << "flights with an axis outside 85–99 % at 2σ, median / worst of the largest error on the ground before "
              << "take-off [m]\n\n| session | n | median | worst | worst step | 1σ cov | 2σ cov | pooled 2σ | outside | on "
              << "the ground before take-off |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [session, rs] : by_session) {
    std::vector<double> rm, st, eg, c1[3], c2[3];
    // the session's airborne samples pooled, and the flights whose 2σ coverage of an axis is outside 85–99 %
    // (filter.md F23f: the pooled figure is what a band calibrated in distribution holds to)
    uwb::Vec3 pooled2 = uwb::Vec3::Zero();
    double n_pooled = 0.0;
    int n_outside = 0;
    for (const Row* r : rs) {
      rm.push_back(r->rmse_air);
      st.push_back(r->step);
      eg.push_back(r->err_ground);
      for (int k = 0; k < 3; ++k) {
        c1[k].push_back(r->cov1(k));
        c2[k].push_back(r->cov2(k));
      }
      if (r->n_cov == 0) continue;
      pooled2 += r->cov2 * static_cast<double>(r->n_cov);
      n_pooled += static_cast<double>(r->n_cov);
      if ((r->cov2.array() < 0.85).any() || (r->cov2.array() > 0.99).any()) ++n_outside;
    }
    if (n_pooled > 0.0) pooled2 /= n_pooled;
    else pooled2.setConstant(std::nan(""));
    out[session] = {{"n", rs.size()}, {"median_rmse_m", median(rm)}, {"worst_rmse_m", maxOf(rm)},
                    {"worst_step_m", maxOf(st)}, {"median_max_error_before_takeoff_m", median(eg)},
                    {"worst_max_error_before_takeoff_m", maxOf(eg)},
                    {"pooled_coverage_2sigma_xyz", {num(pooled2.x()), num(pooled2.y()), num(pooled2.z())}},
                    {"n_flights_2sigma_outside_85_99", n_outside}};
    if (print)
      std::cout << "| " << session << " | " << rs.size() << " | " << fmt3(median(rm)) << " | " << fmt3(maxOf(rm))
                << " | " << fmt3(maxOf(st)) << " | " << pct(median(c1[0])) << "/" << pct(median(c1[1])) << "/"
                << pct(median(c1[2])) << " | " << pct(median(c2[0])) << "/" << pct(median(c2[1])) << "/"
                << pct(median(c2[2])) << " | " << cell(pooled2.x(), 1, 100.0) << "/" << cell(pooled2.y(), 1, 100.0) << "/"
                << cell(pooled2.z(), 1, 100.0)
                << " | " << n_outside << " | " << fmt3(median(eg)) << " / " << fmt3(maxOf(eg)) << " |\n";
  }
  return out;
}

/// One line per set of logs started in the air: their RMSE and their RMSE 3–5 s after the start, each next to the
/// same flight's from the ground on the same window (what remains without the start: the bias field).
void printCutSummary(const std::vector<Row>& sel) {
  std::vector<double> rm, ref, early, early_ref;
  for (const Row& r : sel) {
    rm.push_back(r.rmse_air);
    ref.push_back(r.rmse_ref);
    early.push_back(r.early);
    early_ref.push_back(r.early_ref);
  }
  std::cout << "median RMSE " << fmt3(median(rm)) << " m (full flights on the same windows " << fmt3(median(ref))
            << " m), worst " << fmt3(maxOf(rm)) << " m; RMSE 3–5 s after the start median " << fmt3(median(early))
            << " m, worst " << fmt3(maxOf(early)) << " m (full flights on the same 3–5 s: median "
            << fmt3(median(early_ref)) << " m, worst " << fmt3(maxOf(early_ref)) << " m)\n";
}

/// Time from t1 until the faulted run's estimate is back on the clean run's: the two position estimates at the same
/// truth time (the clean one shifted by `shift_s`, for a clock jump that moved the truth) within 0.15 m of each other
/// for 1 s, and staying so to the end of the airborne part (NaN: never). The filter forgets a fault; whatever error the
/// flight has anyway (the 0426 flights exceed 0.5 m at times without any fault) does not count.
double backOnCleanRun(const uwb::TrajectoryMetrics& faulted, const uwb::TrajectoryMetrics& clean, double t1,
                      double shift_s) {
  double t_rec = std::nan(""), t_good_since = std::nan("");
  std::size_t j = 0;
  for (const uwb::PositionErrorSample& e : faulted.samples) {
    if (!e.airborne || e.t_s < t1) continue;
    const double tc = e.t_s - shift_s;
    while (j + 1 < clean.samples.size() && clean.samples[j + 1].t_s <= tc) ++j;
    if (clean.samples.empty() || std::abs(clean.samples[j].t_s - tc) > 0.05) continue;
    if ((e.w_p_est - clean.samples[j].w_p_est).norm() < 0.15) {
      if (std::isnan(t_good_since)) t_good_since = e.t_s;
      if (std::isnan(t_rec) && e.t_s - t_good_since >= 1.0) t_rec = t_good_since - t1;
    } else {
      t_good_since = std::nan("");
      t_rec = std::nan("");
    }
  }
  return t_rec;
}

/// Error after a fault: the largest airborne error in [t1 + 3, t1 + 6] s and the time from t1 until the error stays
/// below 0.5 m for 1 s (NaN: never).
void recovery(const uwb::TrajectoryMetrics& m, double t1, double* err_after, double* t_recover) {
  *err_after = 0.0;
  *t_recover = std::nan("");
  double t_good_since = std::nan("");
  for (const uwb::PositionErrorSample& e : m.samples) {
    if (!e.airborne || e.t_s < t1) continue;
    if (e.t_s >= t1 + 3.0 && e.t_s <= t1 + 6.0) *err_after = std::max(*err_after, e.error_norm_m);
    if (e.error_norm_m < 0.5) {
      if (std::isnan(t_good_since)) t_good_since = e.t_s;
      if (std::isnan(*t_recover) && e.t_s - t_good_since >= 1.0) *t_recover = t_good_since - t1;
    } else {
      t_good_since = std::nan("");
      *t_recover = std::nan("");
    }
  }
}

/// The fault-injection suite on real dev flights (issue "Nothing a flight or a file can do makes it lie").
void runFaults(const ProtocolArgs& a, const uwb::LocalizationOptions& opt) {
  const std::string data = dataDir(a);
  const std::vector<std::string> names = {"0425-traj2", "0425-traj6", "0426-traj1", "0426-traj11"};
  json rows = json::array();
  if (!a.json_out)
    std::cout << "## Fault injection\n\n| flight | fault | RMSE air clean [m] | RMSE air faulted [m] | ratio | max err 3–6 s "
                 "after [m] | back below 0.5 m after [s] | back on the clean run after [s] | reacq | checks | note |\n"
                 "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const RealFlight& f : realFlights(data)) {
    if (std::find(names.begin(), names.end(), f.name) == names.end()) continue;
    if (!a.only.empty() && f.name.find(a.only) == std::string::npos) continue;
    if (!fs::is_regular_file(f.path)) continue;
    const uwb::AnchorSurvey survey = uwb::readAnchorSurvey(f.survey);
    const uwb::Flight flight = uwb::readFlightCsv(f.path);
    const uwb::LocalizationRun clean = uwb::localizeFlight(flight, survey, opt);
    if (!clean.metrics) continue;
    double t_air0 = std::nan(""), t_air1 = 0.0;
    for (const uwb::PositionErrorSample& e : clean.metrics->samples)
      if (e.airborne) {
        if (std::isnan(t_air0)) t_air0 = e.t_s;
        t_air1 = e.t_s;
      }
    // the checks after the run (eval/RunDiagnostics.h) on the clean flight: no finding expected
    const std::string clean_verdict = uwb::diagnoseRun(flight, survey, opt, clean).verdict();
    if (!a.json_out)
      std::cout << "| " << f.name << " | none | " << fmt3(clean.metrics->airborne.rmse_m) << " | | | | | | "
                << clean.summary.n_reacquisitions << " | " << clean_verdict << " | |\n";
    rows.push_back({{"flight", f.name},
                    {"fault", "none"},
                    {"rmse_airborne_clean_m", clean.metrics->airborne.rmse_m},
                    {"checks", clean_verdict}});
    for (const uwb::FaultSpec& spec : uwb::standardFaults(t_air0 + 3.0, t_air1 - 3.0, survey.anchors.front().id)) {
      uwb::Flight fl = flight;
      uwb::AnchorSurvey sv = survey;
      uwb::injectFault(spec, fl, sv);
      // the localization uses the faulted survey; the truth is the flight's own (the survey fault is the estimator's)
      const uwb::LocalizationRun run = uwb::localizeFlight(fl, sv, opt);
      const double t_end = spec.kind == uwb::FaultKind::kClockJumpAll ? spec.t1_s + 5.0 : spec.t1_s;
      double err_after = std::nan(""), t_rec = std::nan("");
      if (run.metrics) recovery(*run.metrics, t_end, &err_after, &t_rec);
      const double shift = spec.kind == uwb::FaultKind::kClockJumpAll ? 5.0 : 0.0;
      double t_back = run.metrics ? backOnCleanRun(*run.metrics, *clean.metrics, t_end, shift) : std::nan("");
      const double faulted = run.metrics ? run.metrics->airborne.rmse_m : std::nan("");
      const std::string verdict = uwb::diagnoseRun(fl, sv, opt, run).verdict();
      std::string note;
      for (const std::string& n : run.summary.merge.notes()) note += (note.empty() ? "" : "; ") + n;
      if (run.summary.n_time_jumps) note += (note.empty() ? "" : "; ") + std::to_string(run.summary.n_time_jumps) + " time jump(s)";
      if (spec.kind == uwb::FaultKind::kAnchorSurveyOff || spec.kind == uwb::FaultKind::kClockOffsetTdoa ||
          spec.kind == uwb::FaultKind::kSurveyShifted || spec.kind == uwb::FaultKind::kSurveyOtherArena)
        t_rec = t_back = std::nan("");  // whole-flight faults: nothing to recover from
      if (!a.json_out)
        std::cout << "| " << f.name << " | " << uwb::toString(spec.kind) << " | " << fmt3(clean.metrics->airborne.rmse_m)
                  << " | " << fmt3(faulted) << " | " << fmt2(faulted / clean.metrics->airborne.rmse_m) << " | "
                  << fmt3(err_after) << " | " << fmt2(t_rec) << " | " << fmt2(t_back) << " | "
                  << run.summary.n_reacquisitions << " | " << verdict
                  << " | " << note << " |\n";
      rows.push_back({{"flight", f.name},
                      {"fault", uwb::toString(spec.kind)},
                      {"rmse_airborne_clean_m", clean.metrics->airborne.rmse_m},
                      {"rmse_airborne_faulted_m", std::isfinite(faulted) ? json(faulted) : json(nullptr)},
                      {"max_error_3_to_6s_after_m", std::isfinite(err_after) ? json(err_after) : json(nullptr)},
                      {"recover_below_0_5m_s", std::isfinite(t_rec) ? json(t_rec) : json(nullptr)},
                      {"back_on_clean_run_s", std::isfinite(t_back) ? json(t_back) : json(nullptr)},
                      {"n_reacquisitions", run.summary.n_reacquisitions},
                      {"checks", verdict},
                      {"notes", note}});
    }
  }
  if (a.json_out) std::cout << json{{"faults", rows}}.dump() << '\n';
}

/// The sensor-signature matrix (eval/SignatureMatrix.h): every cell against the same flight with its own IMU.
void runSignatures(const ProtocolArgs& a, const uwb::LocalizationOptions& opt) {
  const std::string data = dataDir(a);
  json rows = json::array();
  if (!a.json_out)
    std::cout << "## Sensor-signature matrix\n\n| flight | signature | RMSE air plain [m] | RMSE air [m] | ratio | "
                 "TDoA at in-flight σ | longest on the floor in flight [s] | 2σ coverage x/y/z | TDoA overrules | "
                 "draws passed |\n|---|---|---|---|---|---|---|---|---|---|\n";
  int n_pass = 0, n_rows = 0;
  for (const uwb::SignatureFlight& f : uwb::signatureFlights(data, a.only)) {
    const uwb::LocalizationRun plain = uwb::localizeFlight(f.flight, f.survey, opt);
    for (const uwb::SignatureCell& c : uwb::signatureCells(f.transplant)) {
      const uwb::SignatureRow r = uwb::evaluateSignatureDraws(f, c, plain, opt, a.draws);
      ++n_rows;
      n_pass += r.pass ? 1 : 0;
      std::cerr << "protocol: " << r.flight << " / " << r.cell << " " << fmt3(r.rmse_cell_m) << " m\n";
      if (!a.json_out)
        std::cout << "| " << r.flight << " | " << r.cell << " | " << fmt3(r.rmse_plain_m) << " | " << fmt3(r.rmse_cell_m)
                  << " | " << fmt2(r.ratio) << " | " << pct(r.in_flight_fraction) << " | " << fmt2(r.longest_floor_stuck_s)
                  << " | " << pct(r.coverage_2sigma.x()) << "/" << pct(r.coverage_2sigma.y()) << "/"
                  << pct(r.coverage_2sigma.z()) << " | " << r.mode_overrules << " | "
                  << (r.pass ? "" : "**") << r.n_draws_pass << "/" << r.n_draws << (r.pass ? "" : "**") << " |\n";
      rows.push_back({{"flight", r.flight},
                      {"signature", r.cell},
                      {"rmse_airborne_plain_m", r.rmse_plain_m},
                      {"rmse_airborne_m", r.rmse_cell_m},
                      {"ratio", r.ratio},
                      {"in_flight_fraction", r.in_flight_fraction},
                      {"longest_floor_stuck_s", r.longest_floor_stuck_s},
                      {"coverage_2sigma", {r.coverage_2sigma.x(), r.coverage_2sigma.y(), r.coverage_2sigma.z()}},
                      {"mode_overrules", r.mode_overrules},
                      {"n_draws", r.n_draws},
                      {"n_draws_pass", r.n_draws_pass},
                      {"pass", r.pass}});
    }
  }
  if (a.json_out) std::cout << json{{"signatures", rows}, {"n_pass", n_pass}, {"n", n_rows}}.dump() << '\n';
  else std::cout << "\n" << n_pass << " of " << n_rows << " cells pass in each of " << a.draws
                 << " vibration draws (ratio ≤ 1.2, ≥ 95 % of the airborne TDoA at their in-flight σ, at most 1 s on "
                    "the floor in flight; each figure is the cell's worst draw)\n";
}

/// The statistics of the checks after a run (eval/RunDiagnostics.h) on every real flight, clean and with the
/// faults they are meant to find: how the thresholds were chosen (docs/robustness.md, "Wrong but plausible").
void runChecks(const ProtocolArgs& a, const uwb::LocalizationOptions& opt) {
  const std::string data = dataDir(a);
  json rows = json::array();
  if (!a.json_out)
    std::cout << "## Checks after the run: statistic clean / faulted\n\n| flight | survey rms clean | other arena | "
                 "shifted 10 m: mean error | anchor: top gain, ratio clean | anchor 1 m off: named, offset, gain, ratio | "
                 "clock: lag, power ratio clean | TDoA 0.5 s late: lag, power ratio | verdict clean |\n"
                 "|---|---|---|---|---|---|---|---|---|\n";
  for (const RealFlight& f : realFlights(data)) {
    if (!a.only.empty() && f.name.find(a.only) == std::string::npos) continue;
    if (!fs::is_regular_file(f.path)) continue;
    const uwb::AnchorSurvey survey = uwb::readAnchorSurvey(f.survey);
    const uwb::Flight flight = uwb::readFlightCsv(f.path);
    const auto diagnose = [&](uwb::FaultKind kind, bool faulted) {
      uwb::Flight fl = flight;
      uwb::AnchorSurvey sv = survey;
      if (faulted) uwb::injectFault({kind, 0.0, 1e9, survey.anchors.front().id, 1}, fl, sv);
      const uwb::LocalizationRun run = uwb::localizeFlight(fl, sv, opt);
      uwb::RunDiagnosticParams checks;
      checks.clock_offset = true;  // the table shows what the lag search finds, though it is off in `localize`
      return uwb::diagnoseRun(fl, sv, opt, run, {}, checks);
    };
    const uwb::RunDiagnostics clean = diagnose(uwb::FaultKind::kOutlierBurst, false);
    const uwb::RunDiagnostics arena = diagnose(uwb::FaultKind::kSurveyOtherArena, true);
    const uwb::RunDiagnostics shifted = diagnose(uwb::FaultKind::kSurveyShifted, true);
    const uwb::RunDiagnostics off = diagnose(uwb::FaultKind::kAnchorSurveyOff, true);
    const uwb::RunDiagnostics late = diagnose(uwb::FaultKind::kClockOffsetTdoa, true);
    const auto vec = [](const uwb::Vec3& v) { return json{v.x(), v.y(), v.z()}; };
    rows.push_back({{"flight", f.name},
                    {"survey_rms_clean_m", clean.survey.truncated_rms_m},
                    {"survey_rms_other_arena_m", arena.survey.truncated_rms_m},
                    {"mean_error_shifted_m", vec(shifted.survey.mean_error_m)},
                    {"anchor_top_gain_clean_m", clean.anchors.top_gain_m},
                    {"anchor_top_gain_faulted_m", off.anchors.top_gain_m},
                    {"anchor_ratio_clean", clean.anchors.named_ratio},
                    {"anchor_named_faulted", off.anchors.named_id},
                    {"anchor_offset_faulted_m", vec(off.anchors.named_offset_m)},
                    {"anchor_ratio_faulted", off.anchors.named_ratio},
                    {"clock_done", clean.clock.done},
                    {"clock_lag_clean_s", clean.clock.best_lag_s},
                    {"clock_power_ratio_clean", clean.clock.power_ratio},
                    {"clock_lag_faulted_s", late.clock.best_lag_s},
                    {"clock_power_ratio_faulted", late.clock.power_ratio},
                    {"verdict_clean", clean.verdict()},
                    {"verdicts_faulted",
                     {arena.verdict(), shifted.verdict(), off.verdict(), late.verdict()}}});
    if (a.json_out) continue;
    const std::string named = off.anchors.named_id >= 0 ? std::to_string(off.anchors.named_id) : "none";
    std::cout << "| " << f.name << " | " << fmt3(clean.survey.truncated_rms_m) << " | "
              << fmt3(arena.survey.truncated_rms_m) << " | " << fmt2(shifted.survey.mean_error_m.norm()) << " | "
              << fmt3(clean.anchors.top_gain_m) << ", " << fmt2(clean.anchors.named_ratio) << " | " << named << ", "
              << fmt2(off.anchors.named_offset_m.norm()) << ", " << fmt3(off.anchors.top_gain_m) << ", "
              << fmt2(off.anchors.named_ratio) << " | ";
    if (clean.clock.done)
      std::cout << fmt2(clean.clock.best_lag_s) << ", " << fmt2(clean.clock.power_ratio) << " | "
                << fmt2(late.clock.best_lag_s) << ", " << fmt2(late.clock.power_ratio) << " | ";
    else
      std::cout << "– (no IMU) | – | ";
    std::cout << clean.verdict() << " |\n";
  }
  if (a.json_out) std::cout << json{{"checks", rows}}.dump() << '\n';
}

/// The runs of the protocol, by table, and what the checks after the run said on the landed cuts.
struct ProtocolRows {
  std::vector<Row> full, cuts, sim, sim_cuts;
  // the same cuts logged on to the end, landing included (a log started mid-flight): only the checks after the run
  // are read from them (the survey fit must stay silent: the floor after the landing is not the survey's misfit)
  std::vector<std::string> landed_cut_warnings;
  std::size_t n_landed_cuts = 0;
};

/// The estimate checks' floor (the filter's ground height) and ceiling (the highest anchor).
uwb::EstimateCheckParams estimateCheckParams(const uwb::EkfParams& params, const uwb::AnchorSurvey& survey) {
  uwb::EstimateCheckParams cp;
  cp.floor_z_m = params.ground_z_m;
  cp.ceiling_z_m = -1e300;
  for (const uwb::Anchor& an : survey.anchors) cp.ceiling_z_m = std::max(cp.ceiling_z_m, an.w_p.z());
  return cp;
}

/// A real flight's logs started in the air: cut at each of --cuts, ending 1 s before the last airborne instant of the
/// truth (mid-air); each also logged on to the end, for the checks after the run.
void runCuts(const ProtocolArgs& a, const RealFlight& f, const uwb::Flight& flight, const uwb::AnchorSurvey& survey,
             const uwb::LocalizationRun& full, const uwb::EstimateCheckParams& cp,
             const uwb::LocalizationOptions& opt, ProtocolRows& rows) {
  double t_air_end = -1.0;
  for (const uwb::PositionErrorSample& s : full.metrics->samples)
    if (s.airborne) t_air_end = s.t_s;
  bool survey_written = false;
  for (double t0 : a.cuts) {
    const double t1 = t_air_end - 1.0;
    if (!(t1 > t0 + 5.0)) continue;
    const uwb::Flight cut = uwb::sliceFlight(flight, t0, t1);
    const uwb::LocalizationRun run = uwb::localizeFlight(cut, survey, opt);
    if (!a.write_cuts.empty()) {
      // the cut as the filter sees it, to re-run with `localize`, and once per flight its survey (both atomically)
      uwb::writeFlightCsv(cut, (fs::path(a.write_cuts) / (f.name + "-cut" + cutTime(t0) + ".csv")).string());
      if (!survey_written) {
        uwb::writeAnchorSurvey(survey, (fs::path(a.write_cuts) / (f.name + "-survey.txt")).string());
        survey_written = true;
      }
    }
    Row r = evaluateRun(run, f.name, f.session, "cut at " + cutTime(t0) + " s", cp, cut, survey, opt);
    r.t0 = t0;
    r.t1 = t1;
    if (run.metrics) r.rmse_air = uwb::airborneRmseInWindow(*run.metrics, t0, t1);
    r.rmse_ref = uwb::airborneRmseInWindow(*full.metrics, t0, t1);
    if (!cut.tdoa.empty()) {
      const double ts = cut.tdoa.front().t_s;
      r.early_ref = uwb::airborneRmseInWindow(*full.metrics, ts + 3.0, ts + 5.0);
    }
    rows.cuts.push_back(r);
    const uwb::Flight to_end = uwb::sliceFlight(flight, t0, flight.timeSpan().second);
    ++rows.n_landed_cuts;
    if (evaluateRun(uwb::localizeFlight(to_end, survey, opt), f.name, f.session, "", cp, to_end, survey, opt)
            .survey_warning)
      rows.landed_cut_warnings.push_back(f.name + " (from " + fmt2(t0) + " s to the end)");
  }
}

/// Every real flight whole, and (with IMU and ground truth) its mid-air cuts.
void runRealFlights(const ProtocolArgs& a, const uwb::EkfParams& params, const uwb::LocalizationOptions& opt,
                    ProtocolRows& rows) {
  const std::string data = dataDir(a);
  if (!fs::is_directory(data + "/real"))
    throw uwb::FileError("protocol: no real data under '" + data + "/real' (set --data or $UWBTDOA_DATA)");
  if (!a.write_cuts.empty()) fs::create_directories(a.write_cuts);
  for (const RealFlight& f : realFlights(data)) {
    if (!a.only.empty() && f.name.find(a.only) == std::string::npos) continue;
    if (!fs::is_regular_file(f.path)) {
      std::cerr << "protocol: missing " << f.path << ", skipped\n";
      continue;
    }
    const uwb::AnchorSurvey survey = uwb::readAnchorSurvey(f.survey);
    uwb::FlightReadOptions ro;
    ro.required = {uwb::Stream::kTdoa};
    ro.survey = &survey;
    const uwb::Flight flight = uwb::readFlightCsv(f.path, ro);
    const uwb::EstimateCheckParams cp = estimateCheckParams(params, survey);
    const uwb::LocalizationRun full = uwb::localizeFlight(flight, survey, opt);
    rows.full.push_back(evaluateRun(full, f.name, f.session, flight.hasImu() ? "full" : "full (TDoA only)", cp, flight,
                                    survey, opt));
    std::cerr << "protocol: " << f.name << " full " << fmt3(rows.full.back().rmse_air) << " m\n";
    if (a.no_cuts || !full.metrics || !flight.hasImu()) continue;
    runCuts(a, f, flight, survey, full, cp, opt, rows);
  }
}

/// The simulated scenarios; a run that starts in the air is compared with the same flight logged from the ground.
void runSimulations(const ProtocolArgs& a, const uwb::EkfParams& params, const uwb::LocalizationOptions& opt,
                    ProtocolRows& rows) {
  if (!a.write_sims.empty()) fs::create_directories(a.write_sims);
  for (const uwb::SimScenarioRun& s : uwb::protocolSimulations(dataDir(a), {11, 12, 13}, a.only)) {
    if (!a.write_sims.empty()) {
      // the run as the filter sees it, to re-run with `localize` (both files written atomically)
      uwb::writeFlightCsv(s.flight, (fs::path(a.write_sims) / (s.name + ".csv")).string());
      uwb::writeAnchorSurvey(s.survey, (fs::path(a.write_sims) / (s.name + "-survey.txt")).string());
      if (s.cut) uwb::writeFlightCsv(s.whole, (fs::path(a.write_sims) / (s.name + "-whole.csv")).string());
    }
    const uwb::EstimateCheckParams cp = estimateCheckParams(params, s.survey);
    const uwb::LocalizationRun run = uwb::localizeFlight(s.flight, s.survey, opt);
    Row r = evaluateRun(run, s.name, s.group, s.kind, cp, s.flight, s.survey, opt);
    std::cerr << "protocol: " << s.name << " " << fmt3(r.rmse_air) << " m\n";
    if (!s.cut) {
      rows.sim.push_back(r);
      continue;
    }
    r.t0 = s.flight.timeSpan().first;
    r.t1 = s.flight.timeSpan().second;
    // the same flight logged from the ground: its error on the same window is what the bias field gives
    // without the start in the air
    const uwb::LocalizationRun whole = uwb::localizeFlight(s.whole, s.survey, opt);
    if (whole.metrics) {
      r.rmse_ref = uwb::airborneRmseInWindow(*whole.metrics, r.t0, r.t1);
      if (!s.flight.tdoa.empty()) {
        const double ts = s.flight.tdoa.front().t_s;
        r.early_ref = uwb::airborneRmseInWindow(*whole.metrics, ts + 3.0, ts + 5.0);
      }
    }
    rows.sim_cuts.push_back(r);
  }
}

/// The summaries of the cut tables: per cut time (the development flights, TDoA2, apart from the TDoA3 flight, whose
/// session has a mode of its own) and per simulated group.
void printCutSummaries(const ProtocolArgs& a, const ProtocolRows& rows) {
  for (const bool tdoa2 : {true, false})
    for (double t0 : a.cuts) {
      std::vector<Row> sel;
      for (const Row& r : rows.cuts)
        if (r.t0 == t0 && isDevSession(r.session) == tdoa2) sel.push_back(r);
      if (sel.empty()) continue;
      std::cout << "\n" << (tdoa2 ? "" : "TDoA3, ") << "cut at " << t0 << " s: ";
      printCutSummary(sel);
    }
}

void printSimCutSummaries(const ProtocolRows& rows) {
  std::map<std::string, std::vector<Row>> by_group;
  for (const Row& r : rows.sim_cuts) by_group[r.session].push_back(r);
  for (const auto& [group, sel] : by_group) {
    std::cout << "\n" << group << ": ";
    printCutSummary(sel);
  }
}

/// Every flight here is clean (its own survey, no fault): a warning of the check after the run is a false alarm.
void printFalseAlarms(const ProtocolRows& rows) {
  std::vector<std::string> warned = rows.landed_cut_warnings;
  std::size_t n_runs = rows.n_landed_cuts;
  for (const auto* set : {&rows.full, &rows.cuts, &rows.sim, &rows.sim_cuts})
    for (const Row& r : *set) {
      ++n_runs;
      if (r.survey_warning) warned.push_back(r.name + " (" + r.kind + ")");
    }
  std::cout << "\nSurvey-fit check after the run (eval/RunDiagnostics.h) on these clean runs and on the real cuts logged on to the end, landing included: " << warned.size()
            << " false alarm(s) in " << n_runs << " runs";
  for (std::size_t k = 0; k < warned.size(); ++k) std::cout << (k ? ", " : ": ") << warned[k];
  std::cout << "\n";
}

void printProtocol(const ProtocolArgs& a, const ProtocolRows& rows) {
  std::cout << "## Generalization protocol\n\nFilter parameters: defaults";
  for (const std::string& kv : a.sets) std::cout << ", " << kv;
  std::cout << ". Airborne: ground-truth z > 0.3 m. Coverage: fraction of airborne samples whose per-axis error "
               "is within the reported 1σ / 2σ.\n";
  if (!rows.full.empty()) {
    printTable("Real flights, whole", rows.full, false);
    summarize(rows.full, "Whole real flights", true);
  }
  if (!rows.cuts.empty()) {
    printTable("Real flights cut to start in the air and end before landing", rows.cuts, true);
    printCutSummaries(a, rows);
  }
  if (!rows.sim.empty()) {
    printTable("Simulated flights, whole", rows.sim, false);
    summarize(rows.sim, "Simulated flights", true);
  }
  if (!rows.sim_cuts.empty()) {
    printTable("Simulated flights that start in the air", rows.sim_cuts, true);
    printSimCutSummaries(rows);
  }
  printFalseAlarms(rows);
}

json protocolJson(const ProtocolArgs& a, const ProtocolRows& rows) {
  json j;
  json all = json::array();
  for (const auto* set : {&rows.full, &rows.cuts, &rows.sim, &rows.sim_cuts})
    for (const Row& r : *set) all.push_back(rowJson(r));
  j["rows"] = all;
  j["landed_cuts"] = {{"n", rows.n_landed_cuts}, {"survey_fit_warnings", rows.landed_cut_warnings}};
  j["real_whole_summary"] = summarize(rows.full, "", false);
  j["sim_whole_summary"] = summarize(rows.sim, "", false);
  j["parameters_set"] = a.sets;
  return j;
}

void runProtocol(const ProtocolArgs& a) {
  uwb::EkfParams params;
  for (const std::string& kv : a.sets) applySet(kv, params);
  params.validate();
  uwb::LocalizationOptions opt;
  opt.params = params;
  if (a.faults) {
    runFaults(a, opt);
    return;
  }
  if (a.checks) {
    runChecks(a, opt);
    return;
  }
  if (a.signatures) {
    runSignatures(a, opt);
    return;
  }
  ProtocolRows rows;
  if (!a.no_real) runRealFlights(a, params, opt, rows);
  if (!a.no_sim) runSimulations(a, params, opt, rows);
  if (a.json_out) std::cout << protocolJson(a, rows).dump() << '\n';
  else printProtocol(a, rows);
}

const bool kRegistered = uwb::app::registerCommand(
    {"protocol",
     "Generalization protocol: real flights whole and cut to start in the air, simulated scenarios, coverage",
     [](CLI::App& sub) {
       auto a = std::make_shared<ProtocolArgs>();
       sub.add_option("--data", a->data_dir, "data directory holding real/ (default: $UWBTDOA_DATA or ../shared/data)");
       sub.add_option("--cuts", a->cuts, "start times [s] of the mid-air cuts")->delimiter(',')->capture_default_str();
       sub.add_option("--set", a->sets, "override a filter parameter, name=value (repeatable)");
       sub.add_option("--only", a->only, "only flights/scenarios whose name contains this");
       sub.add_flag("--no-real", a->no_real, "skip the real flights");
       sub.add_flag("--no-sim", a->no_sim, "skip the simulated scenarios");
       sub.add_flag("--no-cuts", a->no_cuts, "skip the mid-air cuts of the real flights");
       sub.add_flag("--faults", a->faults,
                    "run the fault-injection suite on four dev flights instead (outliers, garbage, dead anchor, "
                    "anchor off, IMU dropout, clipping, clock jumps)");
       sub.add_flag("--checks", a->checks,
                    "the statistics of the checks after a run on every real flight, clean and with the faults they "
                    "find (anchor 1 m off, TDoA clock 0.5 s late, survey shifted or of another arena)");
       sub.add_flag("--signatures", a->signatures,
                    "the sensor-signature matrix instead: simulated flights and transplanted dev flights with other "
                    "drones' IMU (rotor vibration, quiet or idling floor, rates, biases, lag), each against the same "
                    "flight with its own IMU");
       sub.add_option("--draws", a->draws,
                      "signature matrix: vibration draws per cell; each figure is the worst draw, a cell passes when "
                      "every draw does")
           ->check(CLI::Range(1, 100))
           ->capture_default_str();
       sub.add_flag("--json", a->json_out, "print one JSON object instead of tables");
       sub.add_option("--write-sims", a->write_sims,
                      "write each simulated run as the filter sees it to this folder (NAME.csv in the UTIL layout, "
                      "NAME-survey.txt; a run cut in the air also as logged from the ground, NAME-whole.csv), to "
                      "re-run it with `localize`");
       sub.add_option("--write-cuts", a->write_cuts,
                      "write each real flight's mid-air cut as the filter sees it to this folder "
                      "(FLIGHT-cutT0.csv in the UTIL layout, FLIGHT-survey.txt), to re-run it with `localize`");
       sub.callback([a] { runProtocol(*a); });
     }});

}  // namespace
