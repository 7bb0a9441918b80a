/** @file Scenario.h
 *  @brief What is simulated: anchors (presets or a survey file) and the reference flight.
 *
 *  Presets: `paper` (8 anchors near the corners of a 7 × 8 × 3 m room, alternating low and high as in the UTIL
 *  arena) and `util-const1` … `util-const4` (the released UTIL constellations, read from
 *  <data_dir>/real/util-final-extract/survey/anchor_const{N}_survey.txt), and `util-pilot-0425` / `util-pilot-0426`
 *  (<data_dir>/real/util-pilot/survey/anchor_{session}_survey.txt). The library reads no environment
 *  variables: the caller passes the data directory (the CLI uses uwb::app::defaultDataDir()).
 */
#pragma once

#include <string>
#include <vector>

#include "uwb/io/AnchorSurvey.h"
#include "uwb/sim/Trajectory.h"

namespace uwb::sim {

struct Scenario {
  AnchorSurvey survey;
  TrajectoryParams trajectory;
};

/// The `paper` constellation (built in, no data needed).
AnchorSurvey paperAnchors();

/// Names accepted by anchorPreset().
std::vector<std::string> anchorPresetNames();

/// Resolves a preset name; `util-const{N}` reads the survey under data_dir (FileError when absent).
/// Throws std::invalid_argument for an unknown name.
AnchorSurvey anchorPreset(const std::string& name, const std::string& data_dir);

/// Centres the pattern on the anchors' bounding box and fits the zigzag raster inside it (margin from the
/// walls in metres, heights between 0.8 m and 0.75 of the lowest high anchor).
void fitTrajectoryToAnchors(const AnchorSurvey& survey, TrajectoryParams* params, double margin_m = 1.0);

/// Convenience: survey + shape + duration, with the trajectory fitted to the anchors.
Scenario makeScenario(AnchorSurvey survey, TrajectoryShape shape, double duration_s);

}  // namespace uwb::sim
