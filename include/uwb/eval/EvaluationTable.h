/** @file EvaluationTable.h
 *  @brief The paper's Fig. 5 table: airborne RMSE without/with bias correction per kernel and number of
 *         inducing points, aggregated over repeats and test flights; written as Markdown, CSV and JSON.
 */
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace uwb {

/// One localization of one test flight with one trained model (one repeat).
struct EvaluationRun {
  std::string kernel;
  int inducing = 0;
  int repeat = 0;
  std::string flight;
  double rmse_uncorrected_m = 0.0;  ///< airborne 3D RMSE without correction
  double rmse_corrected_m = 0.0;    ///< airborne 3D RMSE with the GP correction
  double bias_rmse_before_m = 0.0;  ///< TDoA bias RMSE on the test flight, raw
  double bias_rmse_after_m = 0.0;   ///< TDoA bias RMSE after subtracting the GP mean (ground-truth features)
  double train_seconds = 0.0;
  /// Calibration of the predicted bias on this flight (eval/BiasCalibration.h, docs/math/gp.md P43).
  double coverage_1sigma = 0.0;     ///< fraction of samples with |ε − µ| ≤ σ (nominal 0.683)
  double coverage_2sigma = 0.0;     ///< fraction with |ε − µ| ≤ 2σ (nominal 0.954)
  double nlpd = 0.0;                ///< mean negative log predictive density of ε [nats]
  std::vector<double> coverage;     ///< at calibrationLevels()
};

/// One row of the table: a kernel and a number of inducing points. RMSEs are per flight (airborne samples of one
/// flight), then averaged over test flights and repeats; they are not pooled over the samples of all flights.
struct EvaluationRow {
  std::string kernel;
  int inducing = 0;
  int n_repeats = 0;
  int n_flights = 0;
  double rmse_uncorrected_m = 0.0;  ///< mean over repeats and test flights
  double rmse_corrected_m = 0.0;    ///< mean over repeats and test flights
  /// 100 (corrected / uncorrected − 1) from the means above: NEGATIVE = the correction reduced the error
  /// (e.g. −18.4 %), the one sign convention of the tool, tables, JSON and docs.
  double change_pct = 0.0;
  double change_pct_min = 0.0;      ///< over repeats (each repeat: mean over flights); min = the best repeat
  double change_pct_max = 0.0;
  double bias_rmse_before_m = 0.0;
  double bias_rmse_after_m = 0.0;
  double train_seconds = 0.0;       ///< mean per model
  double coverage_1sigma = 0.0;     ///< mean over repeats and test flights
  double coverage_2sigma = 0.0;
  double nlpd = 0.0;
};

/// Groups runs by (kernel, inducing) in first-seen kernel order and ascending inducing count.
std::vector<EvaluationRow> aggregateRuns(const std::vector<EvaluationRun>& runs);

std::string toMarkdown(const std::vector<EvaluationRow>& rows);
std::string toCsv(const std::vector<EvaluationRow>& rows);
/// JSON array, one object per row (keys as in EvaluationRow; the results.json contract of `evaluate`).
nlohmann::json toJson(const std::vector<EvaluationRow>& rows);
std::string runsToCsv(const std::vector<EvaluationRun>& runs);
/// JSON array, one object per run (every key of EvaluationRun except the coverage curve, plus change_pct).
nlohmann::json runsToJson(const std::vector<EvaluationRun>& runs);
/// Per test flight (repeats averaged) for one configuration: airborne RMSE without/with correction, bias RMSE,
/// 1σ/2σ coverage and NLPD of the predicted bias (docs/math/gp.md P43), as a Markdown table.
std::string perFlightMarkdown(const std::vector<EvaluationRun>& runs, const std::string& kernel, int inducing);

}  // namespace uwb
