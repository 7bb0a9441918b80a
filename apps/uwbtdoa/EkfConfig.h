/** @file EkfConfig.h
 *  @brief `localize --config FILE.json`: a JSON object of EkfParams fields read into EkfParams. Each value is
 *         checked for its type (integers also for their range) before it is converted; errors are InputErrors
 *         naming the file and the key. Fuzzed by fuzz/fuzz_config_json.cpp.
 */
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "uwb/filter/EkfParams.h"

namespace uwb::app {

/// Largest robust_iterations a config may set (EkfParams::validate's bound).
inline constexpr int kMaxRobustIterations = 20;

/// Reads the keys of `j` (names as the EkfParams fields) into `p`; unknown keys are errors. `path` names the file.
void applyEkfConfig(const nlohmann::json& j, const std::string& path, EkfParams& p);

}  // namespace uwb::app
