/** @file FilterOptions.h
 *  @brief The filter options `localize` and `stream` share: `--config FILE.json`, one flag per EkfParams field
 *         (uwb/filter/EkfParamRegistry.h; flags override the file) and `--bias-model`.
 */
#pragma once

#include <CLI/CLI.hpp>
#include <deque>
#include <string>
#include <vector>

#include "uwb/filter/EkfParams.h"
#include "uwb/model/TdoaFeature.h"

namespace uwb::app {

struct FilterOptionArgs {
  std::string config, bias_model;
  /// One CLI option per EkfParams field (uwb::ekfParamRegistry(), same order): the text given, or the bool flag.
  std::deque<std::string> param_text;
  std::deque<bool> param_flag;
  std::vector<CLI::Option*> param_option;
};

/// Adds --config, --bias-model and the per-parameter flags to `sub`; `a` must outlive the parse.
void addFilterOptions(CLI::App& sub, FilterOptionArgs& a);

struct FilterSetup {
  EkfParams params;
  bool process_model_given = false;  ///< by the config file or a flag
  bool start_flag = false;           ///< --start was given
};

/// The parameters from the config file and the flags (validated; InputError naming the file or flag); also checks
/// the tag offset.
FilterSetup buildFilterParams(const FilterOptionArgs& a);

/// The bias model's predictor, or an empty one without --bias-model. Sets params->bias_model_training_level_m from
/// the model file unless it was given (filter.md F24b).
BiasPredictor loadBiasPredictor(const FilterOptionArgs& a, EkfParams* params);

}  // namespace uwb::app
