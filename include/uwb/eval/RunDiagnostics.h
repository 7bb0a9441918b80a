/** @file RunDiagnostics.h
 *  @brief Checks after a localization run that catch the "wrong but plausible" inputs, which the filter itself
 *         cannot tell from a hard flight (docs/robustness.md, "Wrong but plausible"):
 *
 *  - survey fit: the TDoA residuals against the estimated trajectory in flight (a survey of another arena or
 *    with swapped ids does not fit the TDoA), and, with ground truth, a constant offset between the estimate and the
 *    truth (a survey shifted as a whole: TDoA cannot see a translation, the truth can);
 *  - per-anchor survey: leave one anchor out, localize with the others, and fit the left-out anchor's position
 *    offset to the residuals of its pairs by least squares; the anchor whose fitted offset explains the most of its
 *    residuals, clearly more than any other's, is named with the offset (the corrected position is the surveyed
 *    one plus the offset);
 *  - clock offset between the TDoA and IMU streams: localize again with the TDoA stamps shifted by a set of lags
 *    and take the lag with the smallest residual power (IMU-driven runs only: without IMU there is no second clock).
 *
 *  The residual of a TDoA is r = z − h(p̂_tag(t), a_A, a_B) (docs/math/measurement.md M1, M2) at the estimated
 *  pose interpolated at the TDoA stamp; the bias model, if any, is not subtracted. Every statistic is computed
 *  over the estimator's own moving phase (take-off to landing as LocalizerSummary reports them), so it needs no
 *  ground truth.
 *
 *  @code
 *    LocalizationRun run = localizeFlight(flight, survey, opt);
 *    RunDiagnostics d = diagnoseRun(flight, survey, opt, run);
 *    for (const std::string& w : d.warnings()) std::cerr << w << '\n';
 *  @endcode
 */
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "uwb/eval/Localization.h"

namespace uwb {

struct RunDiagnosticParams {
  bool survey_fit = true;    ///< residual level of the whole survey (no re-run)
  bool anchor_survey = true; ///< leave-one-anchor-out offsets (one re-run per anchor)
  /// TDoA/IMU lag search (IMU runs only; clock_lags_s.size() re-runs at most). Off by default: it finds the offset on
  /// simulated flights but not on real ones (docs/robustness.md), so it would only cost time.
  bool clock_offset = false;
  double max_gap_s = 0.1;    ///< trajectory samples farther apart are not interpolated across [s]
  /// Residuals are clipped at this in the residual power and left out of the anchor fits [m]
  /// (kGrossResidual_m of io/ResidualStats.h).
  double gross_residual_m = 1.0;
  /// Survey fit: truncated RMS of the airborne residuals above this → the survey does not fit the TDoA [m]. Clean
  /// dev flights 0.23–0.39 m; docs/robustness.md gives the data.
  double survey_fit_max_rms_m = 0.45;
  /// … and the RMS of the residuals below gross_residual_m above this: a survey that does not fit spreads every
  /// residual; TDoA outliers leave the others as on a clean flight (0.1–0.3 m) [m] (docs/robustness.md).
  double survey_fit_max_inlier_rms_m = 0.35;
  /// Share of gross residuals above this while the others fit: a warning of TDoA outliers, not of the survey.
  double outlier_warn_fraction = 0.1;
  /// With ground truth: the mean airborne error vector longer than this → the survey and the truth are in
  /// different frames [m].
  double max_mean_error_m = 1.0;
  /// Anchor check: the anchor whose fitted offset lowers its pairs' residual RMS the most (the fit gain,
  /// rms_before − rms_after) is named when the gain exceeds this [m] … (clean 0425 flights: at most 0.21 m;
  /// docs/robustness.md gives the data)
  double anchor_min_gain_m = 0.25;
  /// … and is at least this many times the second largest gain (a wrong anchor corrupts its neighbours' runs).
  double anchor_min_gain_ratio = 1.2;
  double anchor_min_residuals = 200;  ///< fewer residuals of an anchor's pairs: no offset fitted
  /// Clock check: the lags tried first [s] (positive: the TDoA stamps are late); then the best one ± half the
  /// grid step and a parabola through the three best.
  std::vector<double> clock_lags_s = {-1.0, -0.5, 0.0, 0.5, 1.0};
  /// A lag is reported when |lag| exceeds this [s] …
  double clock_min_lag_s = 0.15;
  /// … and the residual power at lag 0 is at least this many times the power at the lag.
  double clock_min_power_ratio = 1.15;
};

/// One TDoA's residual against the estimated pose and its anchor Jacobians (M5): r ≈ J_a·δa_A + J_b·δa_B for
/// anchor position errors δa = true − surveyed.
struct EstimateResidual {
  double t_s = 0.0;
  int id_a = -1, id_b = -1;
  double r_m = 0.0;
  RowVec3 J_a = RowVec3::Zero();  ///< ∂z/∂a_A = +u_Aᵀ
  RowVec3 J_b = RowVec3::Zero();  ///< ∂z/∂a_B = −u_Bᵀ
  double w_z_est_m = 0.0;         ///< the estimate's height there [m]
};

/// The residuals of the TDoA in [t0_s, t1_s] whose pair contains `only_anchor` (−1: all) against the trajectory
/// (pose interpolated, io/PoseTrack.h). TDoA with an anchor outside the survey, outside the trajectory or across a
/// gap > max_gap_s are skipped.
std::vector<EstimateResidual> estimateResiduals(const std::vector<TdoaMeasurement>& tdoa, const AnchorSurvey& survey,
                                        const Trajectory& trajectory, const Vec3& b_t_tag, double t0_s, double t1_s,
                                        double max_gap_s, int only_anchor = -1);

/// sqrt(mean_k min(r_k², c²)): the residual power with gross errors clipped at c [m]. 0 for no residuals.
double truncatedRms(const std::vector<EstimateResidual>& residuals, double c_m);

struct SurveyFitCheck {
  bool done = false;
  std::size_t n = 0;              ///< residuals used
  double truncated_rms_m = 0.0;   ///< truncatedRms over the moving phase
  double gross_fraction = 0.0;    ///< fraction of |r| ≥ gross_residual_m
  double inlier_rms_m = 0.0;      ///< RMS of the residuals with |r| < gross_residual_m (0 for none)
  double start_rms_residual_m = 0.0;  ///< the start-up multilateration's residual RMS (LocalizerSummary)
  bool has_truth = false;
  Vec3 mean_error_m = Vec3::Zero();   ///< mean airborne estimate − truth (with ground truth)
  bool misfit = false;            ///< truncated_rms_m > survey_fit_max_rms_m and inlier_rms_m > survey_fit_max_inlier_rms_m
  bool outliers = false;          ///< not misfit, gross_fraction > outlier_warn_fraction: outliers in the TDoA
  bool frame_offset = false;      ///< |mean_error_m| > max_mean_error_m
};

struct AnchorOffset {
  int id = -1;
  std::size_t n = 0;            ///< residuals of the anchor's pairs fitted
  Vec3 offset_m = Vec3::Zero(); ///< least-squares δa (true − surveyed); the corrected position is w_p + offset
  double rms_before_m = 0.0;    ///< truncated RMS of its pairs' residuals against the run without it
  double rms_after_m = 0.0;     ///< … after the offset is applied (linearized)
  double gain_m() const { return rms_before_m - rms_after_m; }
};

struct AnchorSurveyCheck {
  bool done = false;
  std::vector<AnchorOffset> anchors;  ///< one per anchor with enough residuals, by id
  int named_id = -1;                  ///< the anchor whose survey looks wrong (−1: none)
  Vec3 named_offset_m = Vec3::Zero();
  double top_gain_m = 0.0;            ///< the largest fit gain
  double named_ratio = 0.0;           ///< the largest fit gain over the second largest
};

struct ClockOffsetCheck {
  bool done = false;                ///< false without IMU (TDoA-only run)
  std::vector<double> lags_s;       ///< lags tried (positive: TDoA stamps late) [s]
  std::vector<double> rms_m;        ///< truncated residual RMS of the run at each lag [m]
  double best_lag_s = 0.0;          ///< minimizer (parabola through the three best) [s]
  double power_ratio = 1.0;         ///< power at lag 0 / power at the best tried lag
  bool offset = false;              ///< |best_lag_s| > clock_min_lag_s and power_ratio ≥ clock_min_power_ratio
};

/// What the estimator assumed and doubted during the run (filter.md F29d, F30): read from its summary, before any
/// check blames the survey.
struct EstimateDoubts {
  double floor_doubted_s = 0.0;             ///< on the floor by the IMU while the TDoA put the tag in the air [s]
  double floor_doubted_max_height_m = 0.0;  ///< the TDoA's largest height meanwhile [m]
  double inconsistent_s = 0.0;              ///< the TDoA's NIS beyond chance [s]
  std::size_t n_inconsistent_periods = 0;
  double air_shake_rms_radps = 0.0;         ///< the airborne shaking level learned in flight (F29b)
  double duration_s = 0.0;
  /// The survey checks would blame the survey for the estimator's own assumption: more than 2 s on the floor
  /// against the TDoA (F29d).
  bool doubtful() const;
};
EstimateDoubts estimateDoubts(const LocalizationRun& run);

struct RunDiagnostics {
  EstimateDoubts doubts;
  SurveyFitCheck survey;
  AnchorSurveyCheck anchors;
  ClockOffsetCheck clock;
  std::string survey_source;  ///< survey file, named in the warnings
  /// One sentence per finding (empty when all checks pass).
  std::vector<std::string> warnings() const;
  /// The findings in a few words for a table ("anchor 0 named (−0.98, +0.02, −0.05) m; clock +0.48 s"), "silent"
  /// when there is none.
  std::string verdict() const;
};

/// The checks above for `run`, the result of localizeFlight(flight, survey, options, bias). The re-runs use the
/// same options and bias model.
RunDiagnostics diagnoseRun(const Flight& flight, const AnchorSurvey& survey, const LocalizationOptions& options,
                           const LocalizationRun& run, const BiasPredictor& bias = {},
                           const RunDiagnosticParams& params = {});

/// The survey with the named anchor moved by its fitted offset (unchanged when no anchor is named).
AnchorSurvey correctedSurvey(const AnchorSurvey& survey, const AnchorSurveyCheck& check);

}  // namespace uwb
