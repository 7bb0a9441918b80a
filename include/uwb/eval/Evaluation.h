/** @file Evaluation.h
 *  @brief The paper's evaluation (sections III-D, IV; Fig. 5–7): train bias models on training flights, localize
 *         every test flight without and with the GP correction, and collect the table and the figure data.
 *
 *  For each kernel preset, number of inducing points M and repeat r (training seed r + 1), one bias model is
 *  trained on all training flights; each test flight is localized once uncorrected (the filter is
 *  deterministic) and once per model with the correction fed from the filter's own estimate (paper III-D).
 */
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "uwb/eval/BiasDataset.h"
#include "uwb/eval/BiasModel.h"
#include "uwb/eval/EvaluationTable.h"
#include "uwb/eval/Localization.h"

namespace uwb {

struct EvaluationParams {
  std::vector<std::string> kernels{"z1", "z2", "tdoa"};  ///< BiasPreset names
  std::vector<int> inducing{10, 30, 50, 100, 170};       ///< numbers of inducing points M
  int repeats = 3;                                       ///< trainings per (kernel, M), seeds 1..repeats
  BiasTrainParams train;         ///< preset, num_inducing and seed are set per configuration
  BiasDatasetParams dataset;     ///< exclusion rules and GP input source of the training data
  LocalizationOptions localization;
  int threads = 2;               ///< configurations trained/localized in parallel
  double figure_rate_hz = 50.0;  ///< decimation of the per-sample error and trajectory figure data
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// A flight with the name used in tables and figures.
struct NamedFlight {
  std::string name;
  Flight flight;
};

/// Data behind Fig. 7 for one anchor pair: training errors over the two anchor yaw angles and the GP mean.
struct BiasAngleFigure {
  std::string kernel;
  int inducing = 0;
  int id_a = 0, id_b = 0;
  std::vector<double> alpha_a_rad, alpha_b_rad, error_m;  ///< training samples of this pair
  std::vector<double> grid_alpha_a_rad, grid_alpha_b_rad;
  MatX grid_mean_m;  ///< rows: alpha_b, columns: alpha_a
  std::vector<double> inducing_alpha_a_rad, inducing_alpha_b_rad;
  bool valid = false;
};

struct EvaluationResult {
  std::vector<EvaluationRun> runs;
  std::vector<EvaluationRow> rows;
  std::map<std::string, LocalizationRun> uncorrected;  ///< by test flight
  /// Corrected localization of each test flight with the best configuration (most negative change, repeat 1).
  std::map<std::string, LocalizationRun> best_corrected;
  std::string best_kernel;
  int best_inducing = 0;
  /// Airborne error samples per configuration "kernel/M" (all repeats, all test flights), decimated.
  std::map<std::string, std::vector<std::pair<std::string, PositionErrorSample>>> corrected_errors;
  BiasAngleFigure angle_figure;
  std::string dataset_report;  ///< exclusion counts of the training data
  std::size_t n_train_samples = 0;
  bool inputs_from_estimate = false;  ///< GP inputs of the training/test data from the filter (else ground truth)
  double seconds = 0.0;
};

/// Progress messages (one line each) for the CLI's stderr.
using EvaluationProgress = std::function<void(const std::string&)>;

/// Runs the whole evaluation. Throws InputError when a flight lacks ground truth, std::invalid_argument for bad
/// params (e.g. too few training samples for the largest M).
EvaluationResult runEvaluation(const std::vector<NamedFlight>& train, const std::vector<NamedFlight>& test,
                               const AnchorSurvey& survey, const EvaluationParams& params,
                               const EvaluationProgress& progress = {});

/// Writes table.md, table.csv, results.json, runs.csv, figdata/{errors.csv, trajectories.csv, anchors.csv,
/// fig7.json} (the contract of python/uwbtdoa/plots.py) and REPORT.md into dir (created if needed).
/// `command` is the exact command line that produced the result (shown in the report).
void writeEvaluation(const EvaluationResult& result, const AnchorSurvey& survey, const std::string& dir,
                     const std::string& command, const std::vector<std::string>& figures = {});

}  // namespace uwb
