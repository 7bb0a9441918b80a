/** @file cmd_evaluate.cpp
 *  @brief `uwbtdoa evaluate`: the paper's evaluation on any flights (Fig. 5–7, table, REPORT.md).
 *
 *  uwbtdoa evaluate --train F... --test F... --anchors SURVEY.txt [--kernels z1,z2,tdoa]
 *                   [--inducing 10,30,50,100,170] [--repeats 3] [--epochs E] --out DIR [--json] [--no-plots]
 */
#include <fmt/format.h>

#include <filesystem>
#include <map>
#include <stdexcept>

#include "Command.h"
#include "Report.h"
#include "InputGuards.h"
#include "uwb/io/FileAccess.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/UtilCsv.h"

namespace uwb::app {
namespace {

struct Options {
  std::vector<std::string> train, test;
  std::string anchors;
  EvaluationCliOptions eval;
};

/// The name each flight goes by in the results: its file name without extension, or, where two flights share it
/// (a/flight.csv, b/flight.csv), its path without extension, so that no two flights are merged. The same file given
/// twice is an error.
std::vector<std::string> flightNames(const std::vector<std::string>& paths, const char* option) {
  namespace fs = std::filesystem;
  std::map<std::string, int> stems;
  for (const auto& path : paths) ++stems[fs::path(path).stem().string()];
  std::vector<std::string> names;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    for (std::size_t k = 0; k < i; ++k) {
      std::error_code ec;
      if (fs::equivalent(paths[i], paths[k], ec)) {
        throw std::invalid_argument(fmt::format("{}: '{}' and '{}' are the same flight file", option, paths[k], paths[i]));
      }
    }
    const fs::path p(paths[i]);
    names.push_back(stems[p.stem().string()] > 1 ? (p.parent_path() / p.stem()).lexically_normal().string()
                                                  : p.stem().string());
  }
  return names;
}

std::vector<NamedFlight> readFlights(const std::vector<std::string>& paths, const AnchorSurvey& survey,
                                     const char* option) {
  std::vector<NamedFlight> flights;
  FlightReadOptions read_options;
  read_options.required = {Stream::kTdoa, Stream::kPose};
  read_options.survey = &survey;
  const std::vector<std::string> names = flightNames(paths, option);
  for (std::size_t i = 0; i < paths.size(); ++i) flights.push_back({names[i], readFlightCsv(paths[i], read_options)});
  return flights;
}

void setup(CLI::App& sub) {
  auto opt = std::make_shared<Options>();
  sub.add_option("--train", opt->train, "Training flights (UTIL CSV with ground-truth pose)")->required()->check(CLI::ExistingFile);
  sub.add_option("--test", opt->test, "Test flights (UTIL CSV with ground-truth pose)")->required()->check(CLI::ExistingFile);
  sub.add_option("--anchors", opt->anchors, "Anchor survey (UTIL survey text)")->required()->check(CLI::ExistingFile);
  sub.add_option("--out", opt->eval.out_dir, "Output directory for the report")->required();
  opt->eval.addTo(sub);
  sub.callback([opt] {
    checkOutputDirectory(opt->eval.out_dir, "report folder");  // before reading and training
    const AnchorSurvey survey = readAnchorSurvey(opt->anchors);
    Warnings().addIssues(checkSurveyGeometry(survey));
    runAndReport(readFlights(opt->train, survey, "--train"), readFlights(opt->test, survey, "--test"), survey,
                 opt->eval);
  });
}

const bool kRegistered = registerCommand(
    {"evaluate", "Train bias models, localize test flights without/with correction, write the paper's report", setup});

}  // namespace
}  // namespace uwb::app
