/** @file SimConfig.h
 *  @brief `simulate --config params.json`: {"trajectory": {...}, "imu": {...}, "pose": {...}, "tdoa": {...},
 *         "bias": {...}, "b_t_tag": [x, y, z]}; keys are the C++ field names (docs/math/simulation.md). Unknown keys
 *         are errors (typos must not pass silently); values are checked for type and range before conversion.
 *         Fuzzed by fuzz/fuzz_config_json.cpp.
 */
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "uwb/sim/FlightSimulator.h"

namespace uwb::app {

/// Largest integer a simulation config may hold (feature counts, degrees): bounds the memory they size.
inline constexpr int kMaxSimConfigInteger = 10000;

/// Thrown by applySimConfig: the key (section.key) travels with the message so the caller can name file and key.
struct ConfigKeyError : std::invalid_argument {
  ConfigKeyError(std::string k, const std::string& what) : std::invalid_argument(what), key(std::move(k)) {}
  std::string key;
};

/// Applies the JSON object `j` to the parameters; ConfigKeyError on an unknown key or a bad value.
void applySimConfig(const nlohmann::json& j, sim::SimParams* sp, sim::TrajectoryParams* tp);
/// Reads the file, applies it and checks the ranges of the parameters it sets (their validate()); InputError naming
/// the file and the key or section.
void applySimConfigFile(const std::string& path, sim::SimParams* sp, sim::TrajectoryParams* tp);

}  // namespace uwb::app
