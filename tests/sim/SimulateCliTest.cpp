/** @file SimulateCliTest.cpp
 *  @brief `uwbtdoa simulate` end to end: one JSON object on stdout, files written, errors exit non-zero.
 */
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include <unistd.h>

#include "support/CliFixture.h"
#include "uwb/io/UtilCsv.h"

namespace {

using RunResult = uwb::test::CliResult;
RunResult run(const std::string& args) { return uwb::test::runCli(args); }

class SimulateCli : public uwb::test::CliTest {};

TEST_F(SimulateCli, JsonModePrintsOneObjectAndWritesReadableFiles) {
  // GIVEN a short figure-eight simulation with --json
  const std::string flight = path("f.csv");
  const std::string survey = path("s.txt");
  const RunResult r = run("simulate --trajectory figure8 --duration 30 --seed 5 --json --out " + flight +
                          " --survey-out " + survey);
  // THEN it succeeds with exactly one JSON object on stdout
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.at("trajectory"), "figure8");
  EXPECT_GT(j.at("streams").at("tdoa").at("count").get<int>(), 10000);
  EXPECT_LT(std::abs(j.at("residual_airborne").at("median_m").get<double>()), 0.05);
  // AND the written flight and survey read back
  const uwb::Flight f = uwb::readFlightCsv(flight);
  EXPECT_EQ(f.tdoa.size(), j.at("streams").at("tdoa").at("count").get<std::size_t>());
  EXPECT_EQ(uwb::readAnchorSurvey(survey).anchors.size(), 8u);
}

TEST_F(SimulateCli, ConfigOverridesParametersAndRejectsUnknownKeys) {
  // GIVEN a config that switches the bias off, and one with a typo
  const auto good = dir() / "good.json";
  const auto bad = dir() / "bad.json";
  std::ofstream(good) << R"({"bias": {"enabled": false}, "trajectory": {"radius_m": 1.0}})";
  std::ofstream(bad) << R"({"bias": {"noise_sdt_m": 0.1}})";
  const std::string outs = " --out " + path("f.csv") + " --survey-out " + path("s.txt");
  // WHEN we run with each
  const RunResult ok = run("simulate --duration 30 --json --config " + good.string() + outs);
  const RunResult err = run("simulate --duration 30 --json --config " + bad.string() + outs);
  // THEN the first gives noise-free residuals (up to the 1 mm pose rounding), the second fails
  ASSERT_EQ(ok.exit_code, 0) << ok.out;
  EXPECT_LT(nlohmann::json::parse(ok.out).at("residual_airborne").at("mean_abs_dev_m").get<double>(), 0.005);
  EXPECT_NE(err.exit_code, 0);
}

TEST_F(SimulateCli, BadArgumentsExitNonZero) {
  const std::string outs = " --out " + path("f.csv") + " --survey-out " + path("s.txt");
  EXPECT_NE(run("simulate --trajectory spiral" + outs).exit_code, 0);
  EXPECT_NE(run("simulate --duration 5" + outs).exit_code, 0);  // shorter than the ground and ramp phases
  EXPECT_NE(run("simulate --anchors-preset nowhere" + outs).exit_code, 0);
  EXPECT_NE(run("simulate --anchors-file /nonexistent/survey.txt" + outs).exit_code, 0);
}

}  // namespace
