/** @file cmd_inspect.cpp
 *  @brief `uwbtdoa inspect FLIGHT.csv [--anchors SURVEY.txt] [--json]`: streams, TDoA pairs, reader notes, pose
 *  glitches and the TDoA residual against ground truth. The numbers come from uwb::summarizeFlight
 *  (eval/FlightSummary.h); this file only formats them (docs/io.md, "inspect").
 */
#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "Command.h"
#include "uwb/eval/FlightSummary.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/UtilCsv.h"
#include "InputGuards.h"

namespace {

using nlohmann::json;

json statsJson(const uwb::ResidualStats& s) {
  return json{{"n", s.n},
              {"median_m", s.median_m},
              {"mad_m", s.mad_m},
              {"n_gross", s.n_gross},
              {"mean_abs_dev_m", s.mean_abs_dev_m},
              {"median_abs_dev_m", s.median_abs_dev_m},
              {"mean_m", s.mean_m},
              {"rms_m", s.rms_m}};
}

json phaseJson(const uwb::PhaseResiduals& p) {
  return json{{"all", statsJson(p.all)}, {"airborne", statsJson(p.airborne)}, {"ground", statsJson(p.ground)}};
}

json summaryJson(const uwb::FlightSummary& s, const std::string& anchors_path) {
  json j;
  j["file"] = s.source;
  j["anchors"] = anchors_path.empty() ? json(nullptr) : json(anchors_path);
  j["t_start_s"] = s.t_start_s;
  j["t_end_s"] = s.t_end_s;
  j["duration_s"] = s.duration_s;
  json streams = json::object();
  for (const auto& st : s.streams) {
    streams[st.name] = json{{"present", st.present}, {"count", st.count}, {"t_first_s", st.t_first_s},
                            {"t_last_s", st.t_last_s}, {"rate_hz", st.rate_hz}};
  }
  j["streams"] = streams;
  j["n_tdoa"] = s.n_tdoa;
  j["neighbour_pair_fraction"] = s.neighbour_pair_fraction;
  json pairs = json::array();
  for (const auto& p : s.pairs) {
    json jp{{"id_a", p.id_a}, {"id_b", p.id_b}, {"count", p.count}, {"neighbour", p.neighbour}};
    if (s.has_residuals) jp["residual"] = phaseJson(p.residual);
    pairs.push_back(jp);
  }
  j["pairs"] = pairs;
  j["notes"] = s.notes;
  j["has_ground_truth"] = s.has_ground_truth;
  if (s.has_ground_truth) {
    json glitches = json::array();
    for (const auto& g : s.pose_glitches) {
      glitches.push_back(json{{"index", g.index},
                              {"t_s", g.t_s},
                              {"kind", g.kind == uwb::PoseGlitchKind::kAttitude ? "attitude" : "position"},
                              {"magnitude", g.magnitude}});
    }
    j["ground_truth"] = json{{"pose_has_orientation", s.pose_has_orientation},
                             {"airborne_fraction", s.airborne_fraction_pose},
                             {"glitches_attitude", s.n_pose_glitches_attitude},
                             {"glitches_position", s.n_pose_glitches_position},
                             {"glitches", glitches}};
  }
  j["has_residuals"] = s.has_residuals;
  if (s.has_residuals) {
    const auto& r = s.residual_report;
    j["residual"] = phaseJson(s.residual);
    j["residual_neighbour_pairs"] = phaseJson(s.residual_neighbour);
    j["residual_counts"] = json{{"n_measurements", r.n_measurements},
                                {"n_residuals", r.n_residuals},
                                {"n_no_ground_truth", r.n_no_ground_truth},
                                {"n_unknown_anchor", r.n_unknown_anchor}};
  }
  return j;
}

std::string statsCells(const uwb::ResidualStats& s) {
  if (s.n == 0) return fmt::format("{:>7} {:>8} {:>7}", 0, "-", "-");
  return fmt::format("{:>7} {:>+8.3f} {:>7.3f}", s.n, s.median_m, s.mad_m);
}

void printPairs(const uwb::FlightSummary& s) {
  std::cout << fmt::format("\nTDoA pairs: {} measurements, neighbour-pair fraction {:.3f}\n", s.n_tdoa,
                           s.neighbour_pair_fraction);
  if (s.has_residuals) {
    std::cout << "residual r = tdoa_meas - model(ground truth) [m]; mad = mean |r - median| over |r - median| < 1 m "
                 "(MANIFEST.csv definition); air: ground-truth z > 0.3 m\n";
    std::cout << fmt::format("{:<7} {:>3} {:>7} | {:>7} {:>8} {:>7} | {:>7} {:>8} {:>7} | {:>7} {:>8} {:>7}\n",
                             "pair", "nb", "count", "n", "median", "mad", "n_air", "med_air", "mad_air", "n_gnd",
                             "med_gnd", "mad_gnd");
  } else {
    std::cout << fmt::format("{:<7} {:>3} {:>7}\n", "pair", "nb", "count");
  }
  const auto row = [&](const std::string& label, const std::string& nb, std::size_t count,
                       const uwb::PhaseResiduals& r) {
    if (s.has_residuals) {
      std::cout << fmt::format("{:<7} {:>3} {:>7} | {} | {} | {}\n", label, nb, count, statsCells(r.all),
                               statsCells(r.airborne), statsCells(r.ground));
    } else {
      std::cout << fmt::format("{:<7} {:>3} {:>7}\n", label, nb, count);
    }
  };
  for (const auto& p : s.pairs) {
    row(fmt::format("({},{})", p.id_a, p.id_b), p.neighbour ? "*" : "", p.count, p.residual);
  }
  if (s.has_residuals) {
    row("nbrs", "*", s.residual_neighbour.all.n, s.residual_neighbour);
    row("all", "", s.n_tdoa, s.residual);
  }
}

void printHuman(const uwb::FlightSummary& s, const std::string& anchors_path) {
  std::cout << fmt::format("flight    {}\n", s.source);
  if (!anchors_path.empty()) std::cout << fmt::format("anchors   {}\n", anchors_path);
  std::cout << fmt::format("duration  {:.2f} s  ({:.3f} … {:.3f} s)\n\n", s.duration_s, s.t_start_s, s.t_end_s);

  std::cout << fmt::format("{:<8} {:>8} {:>10} {:>10} {:>10}\n", "stream", "count", "rate [Hz]", "first [s]",
                           "last [s]");
  for (const auto& st : s.streams) {
    if (!st.present) continue;
    std::cout << fmt::format("{:<8} {:>8} {:>10.1f} {:>10.3f} {:>10.3f}\n", st.name, st.count, st.rate_hz,
                             st.t_first_s, st.t_last_s);
  }
  std::string absent;
  for (const auto& st : s.streams) {
    if (st.present) continue;
    if (!absent.empty()) absent += ", ";
    absent += st.name;
  }
  if (!absent.empty()) std::cout << fmt::format("(absent: {})\n", absent);

  if (s.n_tdoa == 0) {
    std::cout << "\nTDoA: no measurements\n";
  } else {
    printPairs(s);
  }

  if (s.has_ground_truth) {
    std::cout << fmt::format("\nground truth: {} pose, airborne (z > {} m) {:.1f} % of samples, glitches excluded: "
                             "{} attitude, {} position\n",
                             s.pose_has_orientation ? "full" : "position-only", uwb::kAirborneMinZ_m,
                             100.0 * s.airborne_fraction_pose,
                             s.n_pose_glitches_attitude, s.n_pose_glitches_position);
    for (const auto& g : s.pose_glitches) {
      if (g.kind == uwb::PoseGlitchKind::kAttitude) {
        std::cout << fmt::format("  t = {:9.4f} s  attitude jump {:6.1f} deg\n", g.t_s, g.magnitude * 180.0 / uwb::kPi);
      } else {
        std::cout << fmt::format("  t = {:9.4f} s  position jump {:6.3f} m\n", g.t_s, g.magnitude);
      }
    }
    if (anchors_path.empty() && s.n_tdoa > 0) {
      std::cout << "(pass --anchors SURVEY.txt for the TDoA residual against ground truth)\n";
    }
  } else {
    std::cout << "\nground truth: none (no pose stream)\n";
  }
  if (!s.notes.empty()) {
    std::cout << "\nnotes:\n";
    for (const auto& n : s.notes) std::cout << "  - " << n << '\n';
  }
}

void setup(CLI::App& sub) {
  auto flight_path = std::make_shared<std::string>();
  auto anchors_path = std::make_shared<std::string>();
  auto as_json = std::make_shared<bool>(false);
  sub.add_option("flight", *flight_path, "Flight CSV in the UTIL layout")->required();
  sub.add_option("--anchors,-a", *anchors_path,
                 "Anchor survey (UTIL an{i}_p / an{i}_quat lines); enables the residual against ground truth");
  sub.add_flag("--json", *as_json, "Print exactly one JSON object on stdout");
  sub.callback([flight_path, anchors_path, as_json] {
    uwb::AnchorSurvey survey;
    const bool have_survey = !anchors_path->empty();
    if (have_survey) survey = uwb::readAnchorSurvey(*anchors_path);
    uwb::FlightReadOptions options;
    options.survey = have_survey ? &survey : nullptr;
    uwb::ReadReport report;
    const uwb::Flight flight = uwb::readFlightCsv(*flight_path, options, &report);
    const uwb::FlightSummary summary = uwb::summarizeFlight(flight, have_survey ? &survey : nullptr, &report);
    // inspect is the diagnostic tool: implausible geometry or rates are reported, never fatal here.
    std::vector<uwb::InputIssue> issues = uwb::checkStreamRates(flight);
    if (have_survey) {
      const auto geometry = uwb::checkSurveyGeometry(survey);
      issues.insert(issues.end(), geometry.begin(), geometry.end());
    }
    std::vector<std::string> warnings;
    for (const uwb::InputIssue& i : issues) warnings.push_back(i.text());
    if (*as_json) {
      json j = summaryJson(summary, *anchors_path);
      j["warnings"] = warnings;
      std::cout << uwb::app::dumpJson(j, 2) << '\n';
    } else {
      printHuman(summary, *anchors_path);
      if (!warnings.empty()) {
        std::cout << "\nwarnings:\n";
        for (const auto& w : warnings) std::cout << "  - " << w << '\n';
      }
    }
  });
}

const bool kRegistered = uwb::app::registerCommand({"inspect", "Summarize a flight CSV (streams, pairs, residuals)", setup});

}  // namespace
