/** @file RunDiagnostics.cpp
 *  @brief Survey fit, per-anchor survey offsets (leave one anchor out) and the TDoA/IMU clock lag of a
 *         localization run (docs/robustness.md, "Wrong but plausible").
 */
#include "uwb/eval/RunDiagnostics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>

#include "uwb/io/PoseTrack.h"
#include "uwb/model/TdoaModel.h"

namespace uwb {

namespace {

/// The moving phase the statistics cover: take-off (or, for a log that began in motion, the first fix) to landing as
/// the estimator saw them, else the whole estimate. A log that starts in the air and ends on the floor has its first
/// take-off, if any, after the landing: from there only the floor-level residuals would be counted.
std::pair<double, double> movingWindow(const LocalizationRun& run) {
  const LocalizerSummary& s = run.summary;
  const double t_ready = std::isfinite(s.ready_t_s) ? s.ready_t_s : -1e300;
  const double t0 = std::isfinite(s.takeoff_t_s) && !s.started_in_motion ? s.takeoff_t_s : t_ready;
  const double t1 = std::isfinite(s.landing_t_s) && s.landing_t_s > t0 ? s.landing_t_s : 1e300;
  return {t0, t1};
}

/// Whether t lies in one of the intervals [begin_k, end_k] (an interval without its end runs to the end of the log).
bool inIntervals(double t, const std::vector<double>& begin, const std::vector<double>& end) {
  for (std::size_t k = 0; k < begin.size(); ++k)
    if (t >= begin[k] && t <= (k < end.size() ? end[k] : 1e300)) return true;
  return false;
}

/// The residuals without those of the times the estimator was lost (from each re-acquisition's start to its fix, or
/// to the end): a TDoA fault that the filter caught is not the survey's or the clock's misfit.
std::vector<EstimateResidual> whileTracking(std::vector<EstimateResidual> res, const LocalizerSummary& s) {
  std::erase_if(res, [&](const EstimateResidual& r) { return inIntervals(r.t_s, s.reacquisition_t_s, s.reacquired_t_s); });
  return res;
}

/// The residuals without those of the times the estimator had the body on the ground (rest or floor contact, F18):
/// their TDoA carry the floor-level bias (filter.md F14, F16f), not the survey's error, and weigh the more the shorter
/// the flight (0425-traj9 logged from 20 s: 6 s in the air, 2 s on the floor, 0.50 m with them against 0.37 m).
/// Nor those of the estimate within kLowBand_m of the floor (the descent to a landing and the climb after a
/// take-off): there the TDoA carry the floor-level bias as well (F14, F16h), and an estimate held by the downward
/// range (F21) shows it in full (0425-traj9 logged from 20 s with the ToF: 0.53 m with them).
constexpr double kLowBand_m = 0.5;
std::vector<EstimateResidual> inFlight(std::vector<EstimateResidual> res, const LocalizerSummary& s, double floor_z_m) {
  std::erase_if(res, [&](const EstimateResidual& r) {
    return inIntervals(r.t_s, s.ground_entered_t_s, s.ground_left_t_s) || r.w_z_est_m - floor_z_m < kLowBand_m;
  });
  return res;
}

std::string fmtVec(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%+.2f, %+.2f, %+.2f)", v.x(), v.y(), v.z());
  return buf;
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

SurveyFitCheck checkSurveyFit(const Flight& flight, const AnchorSurvey& survey, const LocalizationOptions& options,
                              const LocalizationRun& run, const RunDiagnosticParams& p) {
  SurveyFitCheck c;
  c.done = true;
  const auto [t0, t1] = movingWindow(run);
  const std::vector<EstimateResidual> res = inFlight(
      whileTracking(
          estimateResiduals(flight.tdoa, survey, run.trajectory, options.params.b_t_tag, t0, t1, p.max_gap_s),
          run.summary),
      run.summary, options.params.ground_z_m);
  c.n = res.size();
  c.truncated_rms_m = truncatedRms(res, p.gross_residual_m);
  const auto n_gross = std::count_if(res.begin(), res.end(),
                                     [&](const EstimateResidual& r) { return std::abs(r.r_m) >= p.gross_residual_m; });
  c.gross_fraction = res.empty() ? 0.0 : static_cast<double>(n_gross) / static_cast<double>(res.size());
  {
    double sum = 0.0;
    std::size_t n_in = 0;
    for (const EstimateResidual& r : res) {
      if (std::abs(r.r_m) >= p.gross_residual_m) continue;
      sum += r.r_m * r.r_m;
      ++n_in;
    }
    c.inlier_rms_m = n_in > 0 ? std::sqrt(sum / static_cast<double>(n_in)) : 0.0;
  }
  c.start_rms_residual_m = run.summary.start_rms_residual_m;
  // a wrong survey spreads every residual; outliers (multipath, a faulty anchor) leave the others small
  c.misfit = c.n > 0 && c.truncated_rms_m > p.survey_fit_max_rms_m && c.inlier_rms_m > p.survey_fit_max_inlier_rms_m;
  c.outliers = c.n > 0 && !c.misfit && c.gross_fraction > p.outlier_warn_fraction;
  if (run.metrics) {
    std::size_t n = 0;
    for (const PositionErrorSample& e : run.metrics->samples)
      if (e.airborne) c.mean_error_m += e.error_m, ++n;
    if (n > 0) {
      c.has_truth = true;
      c.mean_error_m /= static_cast<double>(n);
      c.frame_offset = c.mean_error_m.norm() > p.max_mean_error_m;
    }
  }
  return c;
}

/// Least-squares δa of one anchor from the residuals of its pairs (r ≈ J δa, M5), gross residuals left out.
AnchorOffset fitAnchorOffset(int id, const std::vector<EstimateResidual>& res, double gross_m) {
  AnchorOffset o;
  o.id = id;
  Mat3 A = Mat3::Zero();
  Vec3 b = Vec3::Zero();
  for (const EstimateResidual& r : res) {
    if (std::abs(r.r_m) >= gross_m) continue;
    const RowVec3 J = r.id_a == id ? r.J_a : r.J_b;
    A += J.transpose() * J;
    b += J.transpose() * r.r_m;
    ++o.n;
  }
  o.rms_before_m = truncatedRms(res, gross_m);
  if (o.n == 0) return o;
  // a small ridge keeps a direction the flight does not excite (e.g. the height of a far anchor) near zero
  o.offset_m = (A + 1e-6 * static_cast<double>(o.n) * Mat3::Identity()).ldlt().solve(b);
  std::vector<EstimateResidual> after = res;
  for (EstimateResidual& r : after) r.r_m -= (r.id_a == id ? r.J_a : r.J_b) * o.offset_m;
  o.rms_after_m = truncatedRms(after, gross_m);
  return o;
}

AnchorSurveyCheck checkAnchorSurvey(const Flight& flight, const AnchorSurvey& survey,
                                    const LocalizationOptions& options, const LocalizationRun& run,
                                    const BiasPredictor& bias, const RunDiagnosticParams& p) {
  AnchorSurveyCheck c;
  c.done = true;
  const auto [t0, t1] = movingWindow(run);
  for (const Anchor& a : survey.anchors) {
    Flight without = flight;
    std::erase_if(without.tdoa, [&](const TdoaMeasurement& m) { return m.id_a == a.id || m.id_b == a.id; });
    if (without.tdoa.size() == flight.tdoa.size() || without.tdoa.empty()) continue;  // anchor unused, or alone
    LocalizationOptions opt = options;
    LocalizationRun rerun;
    try {
      rerun = localizeFlight(without, survey, opt, bias);
    } catch (const std::invalid_argument&) {  // the others alone cannot localize (too few anchors)
      continue;
    }
    const std::vector<EstimateResidual> res = whileTracking(
        estimateResiduals(flight.tdoa, survey, rerun.trajectory, options.params.b_t_tag, t0, t1, p.max_gap_s, a.id),
        rerun.summary);
    if (static_cast<double>(res.size()) < p.anchor_min_residuals) continue;
    c.anchors.push_back(fitAnchorOffset(a.id, res, p.gross_residual_m));
  }
  if (c.anchors.size() < 2) return c;
  std::vector<const AnchorOffset*> by_gain;
  for (const AnchorOffset& o : c.anchors) by_gain.push_back(&o);
  std::sort(by_gain.begin(), by_gain.end(), [](const auto* x, const auto* y) { return x->gain_m() > y->gain_m(); });
  c.top_gain_m = by_gain[0]->gain_m();
  c.named_ratio = c.top_gain_m / std::max(by_gain[1]->gain_m(), 1e-6);
  if (c.top_gain_m > p.anchor_min_gain_m && c.named_ratio >= p.anchor_min_gain_ratio) {
    c.named_id = by_gain[0]->id;
    c.named_offset_m = by_gain[0]->offset_m;
  }
  return c;
}

/// Vertex of the parabola through three (x, y) points; the middle x when they are degenerate.
double parabolaVertex(double x0, double y0, double x1, double y1, double x2, double y2) {
  const double d = (x0 - x1) * (x0 - x2) * (x1 - x2);
  const double a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
  const double b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
  if (!(a > 0.0) || !std::isfinite(a) || !std::isfinite(b)) return x1;
  return std::clamp(-b / (2.0 * a), x0, x2);
}

ClockOffsetCheck checkClockOffset(const Flight& flight, const AnchorSurvey& survey,
                                  const LocalizationOptions& options, const LocalizationRun& run,
                                  const BiasPredictor& bias, const RunDiagnosticParams& p) {
  ClockOffsetCheck c;
  if (!flight.hasImu() || options.tdoa_only || run.summary.process_model != ProcessModel::kImu ||
      p.clock_lags_s.empty())
    return c;
  c.done = true;
  const auto window = movingWindow(run);
  const double t0 = window.first, t1 = window.second;  // plain names: the lambda below captures them
  std::map<double, double> power;  // lag → residual power (rms²)
  const auto tryLag = [&](double lag) {
    if (power.count(lag)) return;
    if (lag == 0.0) {
      const double rms = truncatedRms(
          estimateResiduals(flight.tdoa, survey, run.trajectory, options.params.b_t_tag, t0, t1, p.max_gap_s),
          p.gross_residual_m);
      power[lag] = rms * rms;
      return;
    }
    Flight shifted = flight;  // TDoA stamped `lag` late: the true time is t − lag
    for (TdoaMeasurement& m : shifted.tdoa) m.t_s -= lag;
    const LocalizationRun r = localizeFlight(shifted, survey, options, bias);
    // all residuals, lost times included: a wrong lag that loses the estimate is evidence against that lag
    const double rms = truncatedRms(
        estimateResiduals(shifted.tdoa, survey, r.trajectory, options.params.b_t_tag, t0, t1, p.max_gap_s),
        p.gross_residual_m);
    power[lag] = rms * rms;
  };
  tryLag(0.0);
  for (double lag : p.clock_lags_s) tryLag(lag);
  std::vector<double> grid = p.clock_lags_s;
  std::sort(grid.begin(), grid.end());
  double step = grid.size() > 1 ? grid[1] - grid[0] : 0.5;
  const auto best = [&] {
    return std::min_element(power.begin(), power.end(), [](const auto& x, const auto& y) { return x.second < y.second; });
  };
  const double coarse_best = best()->first;
  tryLag(coarse_best - 0.5 * step);
  tryLag(coarse_best + 0.5 * step);
  const auto it = best();
  c.power_ratio = it->second > 0.0 ? power.at(0.0) / it->second : 1.0;
  c.best_lag_s = it->first;
  if (it != power.begin() && std::next(it) != power.end()) {
    const auto lo = std::prev(it), hi = std::next(it);
    c.best_lag_s = parabolaVertex(lo->first, lo->second, it->first, it->second, hi->first, hi->second);
  }
  for (const auto& [lag, pw] : power) {
    c.lags_s.push_back(lag);
    c.rms_m.push_back(std::sqrt(pw));
  }
  c.offset = std::abs(c.best_lag_s) > p.clock_min_lag_s && c.power_ratio >= p.clock_min_power_ratio;
  return c;
}

}  // namespace

std::vector<EstimateResidual> estimateResiduals(const std::vector<TdoaMeasurement>& tdoa, const AnchorSurvey& survey,
                                        const Trajectory& trajectory, const Vec3& b_t_tag, double t0_s, double t1_s,
                                        double max_gap_s, int only_anchor) {
  std::map<int, Vec3> where;
  for (const Anchor& a : survey.anchors) where[a.id] = a.w_p;
  TdoaModelParams model;
  model.b_t_tag = b_t_tag;
  std::vector<EstimateResidual> out;
  for (const TdoaMeasurement& m : tdoa) {
    if (m.t_s < t0_s || m.t_s > t1_s) continue;
    if (only_anchor >= 0 && m.id_a != only_anchor && m.id_b != only_anchor) continue;
    const auto ia = where.find(m.id_a), ib = where.find(m.id_b);
    if (ia == where.end() || ib == where.end() || !std::isfinite(m.tdoa_m)) continue;
    const std::optional<PoseSample> pose = interpolatePose(trajectory, m.t_s, max_gap_s);
    if (!pose) continue;
    TdoaJacobians J;
    const std::optional<double> z = evaluateTdoa(pose->w_p_b, pose->w_q_b, ia->second, ib->second, model, &J);
    if (!z) continue;
    out.push_back({m.t_s, m.id_a, m.id_b, m.tdoa_m - *z, J.J_z_anchor_a, J.J_z_anchor_b, pose->w_p_b.z()});
  }
  return out;
}

double truncatedRms(const std::vector<EstimateResidual>& residuals, double c_m) {
  if (residuals.empty()) return 0.0;
  double sum = 0.0;
  for (const EstimateResidual& r : residuals) sum += std::min(r.r_m * r.r_m, c_m * c_m);
  return std::sqrt(sum / static_cast<double>(residuals.size()));
}

bool EstimateDoubts::doubtful() const { return floor_doubted_s > 2.0; }

EstimateDoubts estimateDoubts(const LocalizationRun& run) {
  EstimateDoubts d;
  d.floor_doubted_s = run.summary.floor_doubted_s;
  d.floor_doubted_max_height_m = run.summary.floor_doubted_max_height_m;
  d.inconsistent_s = run.summary.inconsistent_s;
  d.n_inconsistent_periods = run.summary.n_inconsistent_periods;
  d.air_shake_rms_radps = run.summary.air_shake_rms_radps;
  d.duration_s = run.duration_s;
  return d;
}

RunDiagnostics diagnoseRun(const Flight& flight, const AnchorSurvey& survey, const LocalizationOptions& options,
                           const LocalizationRun& run, const BiasPredictor& bias, const RunDiagnosticParams& params) {
  RunDiagnostics d;
  d.survey_source = survey.source.empty() ? "the survey" : survey.source;
  d.doubts = estimateDoubts(run);
  // (F29d) the survey is checked against an estimate whose mode the TDoA did not doubt: one held on the floor against
  // its TDoA would make any survey look wrong. Innovations beyond chance alone (F30) do not stop the checks: a wrong
  // survey is one of their causes, and the warning of F30 comes first.
  if (d.doubts.doubtful()) return d;
  if (params.survey_fit) d.survey = checkSurveyFit(flight, survey, options, run, params);
  // a survey that does not fit as a whole makes every anchor look wrong: the per-anchor check is not meaningful
  if (params.anchor_survey && !d.survey.misfit) d.anchors = checkAnchorSurvey(flight, survey, options, run, bias, params);
  if (params.clock_offset && !d.survey.misfit) d.clock = checkClockOffset(flight, survey, options, run, bias, params);
  return d;
}

std::vector<std::string> RunDiagnostics::warnings() const {
  std::vector<std::string> w;
  // what the estimator assumed comes first (F29d, F30)
  if (doubts.floor_doubted_s > 1.0)
    w.push_back("ground contact was assumed from the IMU for " + fmt("%.1f", doubts.floor_doubted_s) +
                " s while the TDoA put the tag up to " + fmt("%.2f", doubts.floor_doubted_max_height_m) +
                " m above the floor (the IMU's floor evidence: rest, or gyro shaking above 2× the " +
                fmt("%.2f", doubts.air_shake_rms_radps) +
                " rad/s this flight showed in the air); --ground-phase none ignores the IMU's ground evidence");
  if (doubts.inconsistent_s > 1.0)
    w.push_back("the TDoA disagreed with the estimate beyond chance for " + fmt("%.1f", doubts.inconsistent_s) +
                " s (" + std::to_string(doubts.n_inconsistent_periods) +
                " period(s); mean NIS above 4 for 1 s): the position's σ was widened there");
  if (doubts.doubtful())
    w.push_back("the survey checks were not run: the estimator held the body on the floor against its TDoA (see "
                "above), and a survey cannot be judged against that estimate");
  if (survey.misfit)
    w.push_back("the survey " + survey_source + " does not fit the TDoA: residual RMS " +
                fmt("%.2f", survey.truncated_rms_m) + " m over the flight (clean flights ≤ 0.3 m), " +
                fmt("%.0f", 100.0 * survey.gross_fraction) +
                " % of the residuals above 1 m; is it the survey of this arena, with these anchor ids?");
  if (survey.outliers)
    w.push_back(fmt("%.0f", 100.0 * survey.gross_fraction) + " % of the TDoA are off the estimate by more than 1 m " +
                "while the others fit the survey " + survey_source + " (their RMS " +
                fmt("%.2f", survey.inlier_rms_m) + " m): outliers in the measurements (multipath, an obstructed or " +
                "faulty anchor), not a wrong survey; the filter's gate rejected what it could");
  if (survey.frame_offset)
    w.push_back("the estimate is offset from the flight's ground truth by " + fmtVec(survey.mean_error_m) +
                " m on average: the survey " + survey_source +
                " and the ground truth are not in the same frame (survey shifted? TDoA cannot see a translation)");
  if (anchors.named_id >= 0)
    w.push_back("anchor " + std::to_string(anchors.named_id) + " of " + survey_source +
                " looks mis-surveyed: its TDoA fit a position offset by " + fmtVec(anchors.named_offset_m) + " m (" +
                fmt("%.2f", anchors.named_offset_m.norm()) + " m), which lowers its residual RMS by " +
                fmt("%.2f", anchors.top_gain_m) + " m, " + fmt("%.1f", anchors.named_ratio) +
                "× more than for any other anchor; --fix-survey re-runs with it moved by that offset");
  if (clock.offset)
    w.push_back("the TDoA clock looks " + fmt("%+.2f", clock.best_lag_s) +
                " s off the IMU clock (positive: TDoA stamped late): the residual power is " +
                fmt("%.2f", clock.power_ratio) + "× smaller with the TDoA stamps shifted by that lag");
  return w;
}

std::string RunDiagnostics::verdict() const {
  std::string v;
  const auto add = [&v](const std::string& t) { v += (v.empty() ? "" : "; ") + t; };
  if (doubts.floor_doubted_s > 1.0) add("floor doubted " + fmt("%.1f", doubts.floor_doubted_s) + " s");
  if (doubts.inconsistent_s > 1.0) add("inconsistent " + fmt("%.1f", doubts.inconsistent_s) + " s");
  if (survey.misfit) add("survey misfit (rms " + fmt("%.2f", survey.truncated_rms_m) + " m)");
  if (survey.outliers) add("TDoA outliers " + fmt("%.0f", 100.0 * survey.gross_fraction) + " %");
  if (survey.frame_offset) add("frame offset " + fmtVec(survey.mean_error_m) + " m vs truth");
  if (anchors.named_id >= 0)
    add("anchor " + std::to_string(anchors.named_id) + " named " + fmtVec(anchors.named_offset_m) + " m");
  if (clock.offset) add("clock " + fmt("%+.2f", clock.best_lag_s) + " s");
  return v.empty() ? "silent" : v;
}

AnchorSurvey correctedSurvey(const AnchorSurvey& survey, const AnchorSurveyCheck& check) {
  AnchorSurvey out = survey;
  for (Anchor& a : out.anchors)
    if (a.id == check.named_id) a.w_p += check.named_offset_m;
  return out;
}

}  // namespace uwb
