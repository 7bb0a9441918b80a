/** @file Scenario.cpp
 *  @brief Anchor presets and fitting the reference flight into the anchors' room.
 */
#include "uwb/sim/Scenario.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "uwb/core/Error.h"
#include "uwb/core/Strings.h"
#include "uwb/io/UtilCsv.h"

namespace uwb::sim {

AnchorSurvey paperAnchors() {
  // 8 anchors near the corners of a 7 × 8 × 3 m room, ids ordered like the UTIL arena (anchor_0425_survey.txt):
  // low (0.2 m) and high (2.9 m) alternate along the neighbour pairs (0,1), (1,2), …, (7,0).
  struct Corner {
    double x, y, z;
  };
  constexpr Corner kCorners[8] = {{-3.4, -3.9, 0.2}, {-3.4, 3.9, 2.9}, {3.4, 3.9, 0.2},  {3.4, -3.9, 2.9},
                                  {-3.4, -3.9, 2.9}, {3.4, -3.9, 0.2}, {3.4, 3.9, 2.9},  {-3.4, 3.9, 0.2}};
  AnchorSurvey survey;
  survey.source = "preset:paper";
  for (int i = 0; i < 8; ++i) {
    Anchor a;
    a.id = i;
    a.w_p = Vec3(kCorners[i].x, kCorners[i].y, kCorners[i].z);
    survey.anchors.push_back(a);
  }
  return survey;
}

std::vector<std::string> anchorPresetNames() {
  return {"paper", "util-const1", "util-const2", "util-const3", "util-const4", "util-pilot-0425", "util-pilot-0426"};
}

AnchorSurvey anchorPreset(const std::string& name, const std::string& data_dir) {
  if (name == "paper") return paperAnchors();
  namespace fs = std::filesystem;
  fs::path path;
  if (name.rfind("util-const", 0) == 0 && name.size() == 11 && name[10] >= '1' && name[10] <= '4') {
    path = fs::path(data_dir) / "real" / "util-final-extract" / "survey" /
           ("anchor_const" + std::string(1, name[10]) + "_survey.txt");
  } else if (name == "util-pilot-0425" || name == "util-pilot-0426") {
    path = fs::path(data_dir) / "real" / "util-pilot" / "survey" / ("anchor_" + name.substr(11) + "_survey.txt");
  } else {
    std::string known;
    for (const std::string& n : anchorPresetNames()) appendToList(&known, n);
    throw std::invalid_argument("unknown anchor preset '" + name + "' (expected one of: " + known + ")");
  }
  if (!fs::exists(path)) {
    throw FileError("anchor preset '" + name + "' needs " + path.string() +
                    " (not found; set the data directory, e.g. UWBTDOA_DATA, to the shared/data folder)");
  }
  return readAnchorSurvey(path.string());
}

void fitTrajectoryToAnchors(const AnchorSurvey& survey, TrajectoryParams* params, double margin_m) {
  if (survey.anchors.empty()) throw std::invalid_argument("fitTrajectoryToAnchors: the survey has no anchors");
  Vec3 lo = survey.anchors.front().w_p;
  Vec3 hi = lo;
  double lowest_high_z = 1e9;
  for (const Anchor& a : survey.anchors) {
    lo = lo.cwiseMin(a.w_p);
    hi = hi.cwiseMax(a.w_p);
    if (a.w_p.z() > 1.0) lowest_high_z = std::min(lowest_high_z, a.w_p.z());
  }
  TrajectoryParams& p = *params;
  p.w_center_xy = 0.5 * (lo + hi).head<2>();
  const double half_x = std::max(0.5, 0.5 * (hi.x() - lo.x()) - margin_m);
  const double half_y = std::max(0.5, 0.5 * (hi.y() - lo.y()) - margin_m);
  p.zigzag_half_x_m = half_x;
  p.zigzag_half_y_m = half_y;
  p.zigzag_z_min_m = 0.8;
  p.zigzag_z_max_m = lowest_high_z < 1e9 ? std::clamp(lowest_high_z - 0.6, 0.8, 2.2) : 2.0;
  p.radius_m = std::min(p.radius_m, std::min(half_x, half_y) + margin_m - 0.3);
  p.figure8_half_length_m = std::min(p.figure8_half_length_m, half_x);
  p.figure8_half_width_m = std::min(p.figure8_half_width_m, half_y);
}

Scenario makeScenario(AnchorSurvey survey, TrajectoryShape shape, double duration_s) {
  Scenario s;
  s.survey = std::move(survey);
  s.trajectory.shape = shape;
  s.trajectory.duration_s = duration_s;
  fitTrajectoryToAnchors(s.survey, &s.trajectory);
  return s;
}

}  // namespace uwb::sim
