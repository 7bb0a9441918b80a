/** @file cmd_evaluate.cpp
 *  @brief `uwbtdoa evaluate`: the paper's evaluation on any flights (Fig. 5–7, table, REPORT.md).
 *
 *  uwbtdoa evaluate --train F... --test F... --anchors SURVEY.txt [--kernels z1,z2,tdoa]
 *                   [--inducing 10,30,50,100,170] [--repeats 3] [--epochs E] --out DIR [--json] [--no-plots]
 */
#include <filesystem>

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

std::vector<NamedFlight> readFlights(const std::vector<std::string>& paths, const AnchorSurvey& survey) {
  std::vector<NamedFlight> flights;
  FlightReadOptions read_options;
  read_options.required = {Stream::kTdoa, Stream::kPose};
  read_options.survey = &survey;
  for (const auto& path : paths) {
    flights.push_back({std::filesystem::path(path).stem().string(), readFlightCsv(path, read_options)});
  }
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
    runAndReport(readFlights(opt->train, survey), readFlights(opt->test, survey), survey, opt->eval);
  });
}

const bool kRegistered = registerCommand(
    {"evaluate", "Train bias models, localize test flights without/with correction, write the paper's report", setup});

}  // namespace
}  // namespace uwb::app
