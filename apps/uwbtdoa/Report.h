/** @file Report.h
 *  @brief Shared by `evaluate` and `demo`: run the evaluation from CLI options and render the figures with the
 *         Python package's `uwbtdoa.plots` (one implementation of each figure, also used from Python).
 */
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "uwb/eval/Evaluation.h"

namespace uwb::app {

/// Adds the evaluation options shared by `evaluate` and `demo` (kernels, inducing, repeats, epochs, ...).
struct EvaluationCliOptions {
  std::vector<std::string> kernels{"z1", "z2", "tdoa"};
  std::vector<int> inducing{10, 30, 50, 100, 170};
  int repeats = 3;
  int epochs = 0;      ///< 0: the trainer's default
  int batch = 0;       ///< 0: the trainer's default
  int threads = 2;
  std::string inputs = "estimate";  ///< GP inputs of the training data: "estimate" (filter) or "truth"
  bool no_plots = false;
  bool full_variance = false;  ///< the models ask the filter for the scaled TDoA variance (docs/math/gp.md P45)
  bool bias_guard = EkfParams{}.bias_guard;  ///< corrected runs with the bias guard (docs/math/filter.md F24)
  bool json = false;
  std::string out_dir;
  void addTo(CLI::App& sub);
  EvaluationParams toParams() const;
};

/// Runs `python3 -m uwbtdoa.plots ARGS...` with an argument vector (posix_spawn, no shell: no character of an
/// argument is interpreted); returns what it printed on stdout. Throws FileError on failure.
std::string runPlots(const std::vector<std::string>& args);

/// Runs `python3 -m uwbtdoa.plots report DIR`; returns the PNG file names written. Throws on failure.
std::vector<std::string> renderFigures(const std::string& dir);

/// Runs the evaluation, writes DIR, renders the figures, prints the table (or one JSON object with --json).
void runAndReport(const std::vector<NamedFlight>& train, const std::vector<NamedFlight>& test,
                  const AnchorSurvey& survey, const EvaluationCliOptions& options);

}  // namespace uwb::app
