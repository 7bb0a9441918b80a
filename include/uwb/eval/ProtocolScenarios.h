/** @file ProtocolScenarios.h
 *  @brief The simulated flights of the generalization protocol (`uwbtdoa protocol`): what real data cannot show.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"

namespace uwb {

struct SimScenarioRun {
  std::string name;   ///< scenario, layout and seed
  std::string group;  ///< scenario name (summaries per scenario)
  std::string kind;
  Flight flight;
  AnchorSurvey survey;
  bool cut = false;   ///< the log starts in the air
  /// For a cut: the simulated flight from the ground that the log was cut from (the reference on the same window:
  /// what the error is there without the start in the air); empty otherwise.
  Flight whole;
};

/// Start in hover, a 16 s still hover, two take-offs, fast flight, a yawing start in the air, carried by a walking
/// person (log started while walking); each over the seeds
/// (the drone and room: bias field_seed = seed) and anchor layouts (the paper's, the same moved and turned, and UTIL
/// constellation 4 when data_dir holds it). `only` keeps the scenarios whose name contains it.
std::vector<SimScenarioRun> protocolSimulations(const std::string& data_dir,
                                                const std::vector<std::uint64_t>& seeds = {11, 12, 13},
                                                const std::string& only = "");

}  // namespace uwb
