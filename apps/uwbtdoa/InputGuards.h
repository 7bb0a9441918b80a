/** @file InputGuards.h
 *  @brief Checks the subcommands share: outputs writable before the work, plausible CLI values, survey and stream
 *         plausibility (errors stop the command, warnings go to stderr and into the `--json` object), and JSON
 *         printing that never fails on a file name that is not UTF-8.
 */
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "uwb/core/Types.h"
#include "uwb/filter/SensorRange.h"
#include "uwb/io/AnchorSurvey.h"
#include "uwb/io/InputChecks.h"

namespace uwb::app {

/// Warnings a command collects for its report (`--json` "warnings"), each also printed on stderr when added.
class Warnings {
 public:
  void add(const std::string& text);
  /// Throws InputError on the first error of `issues`; adds the warnings.
  void addIssues(const std::vector<InputIssue>& issues);
  const std::vector<std::string>& list() const { return list_; }

 private:
  std::vector<std::string> list_;
};

/// JSON text for stdout; invalid UTF-8 (e.g. in a file name) is replaced instead of throwing.
std::string dumpJson(const nlohmann::json& j, int indent = -1);

/// A position given on the command line must lie near the anchors: within `margin_m` of their bounding box.
/// InputError naming the option otherwise (e.g. `--start 1e6,0,0`).
inline constexpr double kMaxDistanceOutsideAnchors_m = 20.0;
void checkNearAnchors(const Vec3& w_p, const AnchorSurvey& survey, const std::string& option,
                      double margin_m = kMaxDistanceOutsideAnchors_m);

/// A time step option (e.g. `--output-period`): finite and in (0, max_s]. InputError naming the option otherwise.
void checkPeriod(double value_s, const std::string& option, double max_s);

}  // namespace uwb::app
