/** @file ProtocolScenarios.h
 *  @brief The simulated flights of the generalization protocol (`uwbtdoa protocol`): what real data cannot show.
 */
#pragma once

#include <string>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/Flight.h"

namespace uwb::app {

struct SimScenarioRun {
  std::string name;   ///< scenario, layout and seed
  std::string group;  ///< scenario name (summaries per scenario)
  std::string kind;
  Flight flight;
  AnchorSurvey survey;
  bool cut = false;   ///< the log starts in the air
};

/// Start in hover, a 10 s still hover, two take-offs, fast flight; each over several seeds, anchor layouts and
/// bias fields (drones and rooms).
std::vector<SimScenarioRun> protocolSimulations();

}  // namespace uwb::app
