/** @file ProtocolCliTest.cpp
 *  @brief `uwbtdoa protocol --json` on one real flight: each row carries the figures the protocol's tables print,
 *         the flight's bias level among them (docs/math/filter.md F23c), and the session summary matches the row.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>

#include "support/TestSupport.h"

namespace uwb {
namespace {

/// The protocol on 0425-traj2 alone; skips where the CLI or the real data is absent.
class ProtocolCli : public ::testing::Test {
 protected:
  void SetUp() override {
    UWB_REQUIRE_CLI();
    UWB_REQUIRE_REAL_DATA(test::pilotFlight("0425-traj2"));
  }
  /// `uwbtdoa protocol --json --no-sim` on the flight with `options`; its JSON output.
  nlohmann::json run(const std::string& options) {
    out_ = test::runCli("protocol --data " + test::dataDir().string() + " --only 0425-traj2 --no-sim --json " +
                        options);
    EXPECT_EQ(out_.exit_code, 0) << out_.err;
    return nlohmann::json::parse(out_.out);
  }
  test::CliResult out_;
};

TEST_F(ProtocolCli, JsonRowsCarryTheFiguresAndTheFlightsBiasLevel) {
  // WHEN the protocol runs on that one whole flight (no cuts, no simulations)
  const nlohmann::json j = run("--no-cuts");
  // THEN there is one row, with its RMSE, coverage and the level the filter measured in flight
  const nlohmann::json& rows = j.at("rows");
  ASSERT_EQ(rows.size(), 1u) << out_.out.substr(0, 2000);
  const nlohmann::json& row = rows.at(0);
  EXPECT_EQ(row.at("name").get<std::string>(), "0425-traj2");
  const double rmse = row.at("rmse_airborne_m").get<double>();
  EXPECT_GT(rmse, 0.1);
  EXPECT_LT(rmse, 0.3);
  const double level = row.at("bias_level_m").get<double>();
  EXPECT_GT(level, 0.1);
  EXPECT_LT(level, 0.5);
  for (int k = 0; k < 3; ++k) {
    const double c1 = row.at("coverage_1sigma_xyz").at(k).get<double>(), c2 = row.at("coverage_2sigma_xyz").at(k).get<double>();
    EXPECT_GT(c1, 0.0);
    EXPECT_LE(c1, c2);
    EXPECT_LE(c2, 1.0);
  }
  EXPECT_EQ(row.at("session").get<std::string>(), "0425");
  EXPECT_FALSE(row.at("survey_fit_warning").get<bool>());  // the check after the run is silent on a clean flight
  // and the session's summary pools its airborne samples: with one flight, that flight's 2σ coverage; it counts the
  // flight as outside 85–99 % exactly when one of its axes is
  const nlohmann::json& session = j.at("real_whole_summary").at("0425");
  bool outside = false;
  for (int k = 0; k < 3; ++k) {
    const double c2 = row.at("coverage_2sigma_xyz").at(k).get<double>();
    EXPECT_NEAR(session.at("pooled_coverage_2sigma_xyz").at(k).get<double>(), c2, 1e-12);
    outside = outside || c2 < 0.85 || c2 > 0.99;
  }
  EXPECT_EQ(session.at("n_flights_2sigma_outside_85_99").get<int>(), outside ? 1 : 0);
}

TEST_F(ProtocolCli, TheCutsAreAlsoLoggedToTheLandingAndTheSurveyCheckStaysSilentOnThem) {
  // WHEN the protocol cuts one flight at 10 s
  const nlohmann::json j = run("--cuts 10");
  // THEN the whole flight and the cut ending mid-air are rows, the cut logged on to the end (landing included) is
  // counted, and no run warns of a survey misfit
  ASSERT_EQ(j.at("rows").size(), 2u);
  for (const nlohmann::json& row : j.at("rows")) EXPECT_FALSE(row.at("survey_fit_warning").get<bool>());
  EXPECT_EQ(j.at("landed_cuts").at("n").get<int>(), 1);
  EXPECT_TRUE(j.at("landed_cuts").at("survey_fit_warnings").empty()) << j.at("landed_cuts").dump();
}

TEST_F(ProtocolCli, AWrittenCutGivesTheSameResultWithLocalize) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("uwb_protocol_cuts_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  // WHEN the protocol cuts one flight at 7.5 s and writes the cut
  const nlohmann::json j = run("--cuts 7.5 --write-cuts " + dir.string());
  ASSERT_EQ(j.at("rows").size(), 2u);
  const nlohmann::json& cut = j.at("rows").at(1);
  EXPECT_EQ(cut.at("kind").get<std::string>(), "cut at 7.5 s");
  const std::filesystem::path csv = dir / "0425-traj2-cut7.5.csv", survey = dir / "0425-traj2-survey.txt";
  ASSERT_TRUE(std::filesystem::exists(csv));
  ASSERT_TRUE(std::filesystem::exists(survey));
  // THEN `localize` on the written cut gives the protocol's airborne RMSE of the cut (the log as the filter saw it)
  const test::CliResult l =
      test::runCli("localize " + csv.string() + " --anchors " + survey.string() + " --json --no-diagnostics");
  ASSERT_EQ(l.exit_code, 0) << l.err;
  const double protocol_rmse = cut.at("rmse_airborne_m").get<double>();
  EXPECT_GT(protocol_rmse, 0.05);
  EXPECT_NEAR(nlohmann::json::parse(l.out).at("rmse_airborne_m").get<double>(), protocol_rmse, 1e-9);
  std::filesystem::remove_all(dir);
}

TEST(ProtocolCliSims, AWrittenSimulatedRunGivesTheSameResultWithLocalize) {
  UWB_REQUIRE_CLI();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("uwb_protocol_sims_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  // WHEN the protocol writes the one simulated hover start it runs (built-in layout: no data folder needed)
  const test::CliResult r =
      test::runCli("protocol --no-real --only hover-start-paper-s11 --json --write-sims " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("rows").size(), 1u);
  const std::string name = "hover-start-paper-s11";
  for (const char* suffix : {".csv", "-survey.txt", "-whole.csv"})
    EXPECT_TRUE(std::filesystem::exists(dir / (name + suffix))) << suffix;
  // THEN `localize` on the written files gives the protocol's airborne RMSE (the run as the filter saw it)
  const test::CliResult l = test::runCli("localize " + (dir / (name + ".csv")).string() + " --anchors " +
                                         (dir / (name + "-survey.txt")).string() + " --json --no-diagnostics");
  ASSERT_EQ(l.exit_code, 0) << l.err;
  const double protocol_rmse = j.at("rows").at(0).at("rmse_airborne_m").get<double>();
  EXPECT_GT(protocol_rmse, 0.05);
  EXPECT_NEAR(nlohmann::json::parse(l.out).at("rmse_airborne_m").get<double>(), protocol_rmse, 1e-9);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace uwb
