/** @file cmd_survey.cpp
 *  @brief `uwbtdoa survey ANCHORS.yaml [--out SURVEY.txt] [--flight FLIGHT.csv] [--trajectory TRAJ] [--json]`: the
 *         anchor positions a Crazyflie user has (the cfclient Loco Positioning tab's saved YAML, or a UTIL survey)
 *         as the survey the other commands read, checked: colocated anchors, anchors in one plane, a flight that
 *         leaves the anchors' box, anchor ids of the flight missing from the survey (io/SurveyCheck.h,
 *         docs/crazyflie.md).
 */
#include <fmt/format.h>

#include <iostream>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "Command.h"
#include "InputGuards.h"
#include "uwb/core/Error.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/SurveyCheck.h"
#include "uwb/io/TrajectoryCsv.h"
#include "uwb/io/UtilCsv.h"

namespace {

using nlohmann::json;

struct SurveyArgs {
  std::string anchors, out, flight, trajectory;
  bool json_out = false;
};

/// The first line that is neither blank nor a comment.
std::string firstContentLine(const std::string& text) {
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    const std::size_t b = line.find_first_not_of(" \t\r");
    if (b != std::string::npos && line[b] != '#' && line.compare(b, 3, "---") != 0) return line.substr(b);
    start = end + 1;
  }
  return "";
}

/// A UTIL survey (`an0_p,…`) or cfclient's YAML, told apart by the first line.
uwb::AnchorSurvey readAnyAnchors(const std::string& path, std::string& format) {
  const std::string text = uwb::readTextFile(path, "anchor positions");
  if (firstContentLine(text).rfind("an", 0) == 0) {
    format = "util";
    return uwb::parseAnchorSurvey(text, path);
  }
  format = "cfclient-yaml";
  return uwb::parseCfclientAnchors(text, path);
}

/// Positions of the flight for the volume check: its motion capture, else the trajectory given (CSV or TUM).
std::vector<uwb::Vec3> flightPositions(const uwb::Flight* flight, const std::string& trajectory, std::string& from) {
  std::vector<uwb::Vec3> out;
  if (!trajectory.empty()) {
    const std::string text = uwb::readTextFile(trajectory, "trajectory file");
    const uwb::Trajectory t = text.rfind('#', 0) == 0 ? uwb::parseTrajectoryTum(text, trajectory)
                                                       : uwb::parseTrajectoryCsv(text, trajectory);
    for (const uwb::TrajectorySample& s : t) out.push_back(s.w_p_b);
    from = trajectory;
  } else if (flight != nullptr && !flight->pose.empty()) {
    for (const uwb::PoseSample& p : flight->pose) out.push_back(p.w_p_b);
    from = flight->source + " (motion capture)";
  }
  return out;
}

void runSurvey(const SurveyArgs& a) {
  if (!a.out.empty()) uwb::checkOutputFile(a.out, "survey file");
  std::string format;
  const uwb::AnchorSurvey survey = readAnyAnchors(a.anchors, format);
  std::optional<uwb::Flight> flight;
  if (!a.flight.empty()) flight = uwb::readFlightCsv(a.flight);
  std::string positions_from;
  const std::vector<uwb::Vec3> positions = flightPositions(flight ? &*flight : nullptr, a.trajectory, positions_from);
  std::vector<std::string> notes;
  if (positions.empty() && flight) {
    notes.push_back("the flight has no motion capture: give --trajectory (the output of `localize`) to check that "
                    "the anchors surround it");
  }
  uwb::app::Warnings warnings;  // stops on an error (no position can be computed from the anchors)
  warnings.addIssues(uwb::checkSurvey(survey, flight ? &*flight : nullptr, positions, positions_from));
  if (!a.out.empty()) uwb::writeAnchorSurvey(survey, a.out);

  if (a.json_out) {
    json anchors = json::array();
    for (const uwb::Anchor& an : survey.anchors) anchors.push_back({{"id", an.id}, {"p", {an.w_p.x(), an.w_p.y(), an.w_p.z()}}});
    const json j{{"anchors_file", a.anchors},       {"format", format},
                 {"out", a.out.empty() ? json(nullptr) : json(a.out)},
                 {"n_anchors", survey.anchors.size()}, {"anchors", anchors},
                 {"n_positions_checked", positions.size()}, {"warnings", warnings.list()},
                 {"notes", notes}};
    std::cout << uwb::app::dumpJson(j, 2) << '\n';
    return;
  }
  std::cout << fmt::format("{} anchors from {} ({})\n", survey.anchors.size(), a.anchors, format);
  std::cout << fmt::format("{:>4} {:>9} {:>9} {:>9}\n", "id", "x [m]", "y [m]", "z [m]");
  for (const uwb::Anchor& an : survey.anchors)
    std::cout << fmt::format("{:>4} {:>9.3f} {:>9.3f} {:>9.3f}\n", an.id, an.w_p.x(), an.w_p.y(), an.w_p.z());
  if (!positions.empty()) std::cout << fmt::format("flight volume checked on {} positions of {}\n", positions.size(), positions_from);
  for (const std::string& n : notes) std::cout << "note: " << n << "\n";
  std::cout << fmt::format("{} warning(s){}\n", warnings.list().size(), warnings.list().empty() ? "" : " (above, on stderr)");
  if (!a.out.empty()) std::cout << "survey written to " << a.out << "\n";
}

const bool kRegistered = uwb::app::registerCommand(
    {"survey", "Turn the Crazyflie client's anchor positions (YAML) into a survey and check it against a flight",
     [](CLI::App& sub) {
       auto a = std::make_shared<SurveyArgs>();
       sub.add_option("anchors", a->anchors,
                      "Anchor positions: the YAML the Crazyflie client's Loco Positioning tab saves, or a UTIL "
                      "survey")
           ->required();
       sub.add_option("--out", a->out, "Write the survey (UTIL survey text, for --anchors) here");
       sub.add_option("--flight", a->flight,
                      "Flight CSV (e.g. from `import`): check its anchor ids, and its motion capture against the "
                      "anchors' box");
       sub.add_option("--trajectory", a->trajectory,
                      "Estimated trajectory (CSV or TUM from `localize`) to check against the anchors' box when the "
                      "flight has no motion capture");
       sub.add_flag("--json", a->json_out, "Print one JSON object");
       sub.callback([a] { runSurvey(*a); });
     }});

}  // namespace
