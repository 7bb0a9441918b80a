/** @file FlightSummaryTest.cpp
 *  @brief Flight summary behind `uwbtdoa inspect`: statistics, neighbour pairs, and agreement with
 *  util-pilot/MANIFEST.csv on every real flight (RealData* suites skip when the data is absent).
 */
#include "uwb/eval/FlightSummary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/IoTestHelpers.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

TEST(ResidualStats, MedianAndBothMads) {
  // GIVEN residuals with one gross error (5 m)
  const std::vector<double> r = {0.1, -0.2, 0.3, 0.0, 5.0};
  // WHEN summarised
  const ResidualStats s = residualStats(r);
  // THEN median 0.1; mad over |r − 0.1| < 1 m = (0 + 0.3 + 0.2 + 0.1) / 4; the gross error is counted
  EXPECT_EQ(s.n, 5u);
  EXPECT_DOUBLE_EQ(s.median_m, 0.1);
  EXPECT_NEAR(s.mad_m, 0.15, 1e-12);
  EXPECT_EQ(s.n_gross, 1u);
  EXPECT_NEAR(s.mean_abs_dev_m, (0.0 + 0.3 + 0.2 + 0.1 + 4.9) / 5.0, 1e-12);
  EXPECT_NEAR(s.median_abs_dev_m, 0.2, 1e-12);
  EXPECT_NEAR(s.mean_m, 5.2 / 5.0, 1e-12);
}

TEST(ResidualStats, EvenCountMedianAndEmptyInput) {
  EXPECT_DOUBLE_EQ(residualStats({1.0, 3.0, 2.0, 4.0}).median_m, 2.5);
  const ResidualStats empty = residualStats({});
  EXPECT_EQ(empty.n, 0u);
  EXPECT_EQ(empty.mad_m, 0.0);
}

TEST(FlightSummary, NeighbourPairsAreCyclicSuccessors) {
  const std::vector<int> ids = {0, 1, 2, 3, 4, 5, 6, 7};
  EXPECT_TRUE(isNeighbourPair(0, 1, ids));
  EXPECT_TRUE(isNeighbourPair(7, 0, ids));
  EXPECT_FALSE(isNeighbourPair(1, 0, ids));
  EXPECT_FALSE(isNeighbourPair(1, 3, ids));
  EXPECT_FALSE(isNeighbourPair(9, 0, ids));
  EXPECT_TRUE(isNeighbourPair(12, 3, {3, 5, 12}));
}

TEST(FlightSummary, CountsStreamsPairsAndRates) {
  // GIVEN a flight with TDoA at 100 Hz on three pairs, no pose
  Flight f;
  f.columns = {"t_tdoa", "idA", "idB", "tdoa_meas"};
  for (int i = 0; i <= 100; ++i) f.tdoa.push_back({0.01 * i, i % 2 == 0 ? 0 : 1, i % 2 == 0 ? 1 : 3, 0.0});
  f.tdoa.back().id_a = 7;
  f.tdoa.back().id_b = 0;
  // WHEN summarised without a survey
  ReadReport report;
  report.notes = {"a reader note"};
  const FlightSummary s = summarizeFlight(f, nullptr, &report);
  // THEN streams, pairs and the neighbour fraction are reported; no ground truth, no residuals
  EXPECT_NEAR(s.duration_s, 1.0, 1e-12);
  const auto& tdoa = s.streams[1];
  EXPECT_EQ(tdoa.name, "tdoa");
  EXPECT_EQ(tdoa.count, 101u);
  EXPECT_NEAR(tdoa.rate_hz, 100.0, 1e-9);
  EXPECT_FALSE(s.streams[0].present) << "twr";
  ASSERT_EQ(s.pairs.size(), 3u);
  EXPECT_EQ(s.pairs[0].id_a, 0);
  EXPECT_EQ(s.pairs[0].count, 50u) << "(0,1) on even i < 100";
  EXPECT_TRUE(s.pairs[0].neighbour);
  EXPECT_FALSE(s.pairs[1].neighbour) << "(1,3)";
  EXPECT_TRUE(s.pairs[2].neighbour) << "(7,0) with ids 0..7";
  EXPECT_NEAR(s.neighbour_pair_fraction, 51.0 / 101.0, 1e-12);
  EXPECT_FALSE(s.has_ground_truth);
  EXPECT_FALSE(s.has_residuals);
  EXPECT_THAT(s.notes, ::testing::Contains(std::string("a reader note")));
}

// ------------------------------------------------------------------------------------------------ real data

struct ManifestRow {
  std::string file, session, survey;
  std::size_t n_uwb = 0, n_acc = 0, n_gyro = 0, n_pose = 0, n_tof = 0, n_flow = 0, n_baro = 0;
  double duration_s = 0, neighbour_fraction = 0, median_m = 0, mad_m = 0;
};

std::vector<ManifestRow> readManifest(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  std::vector<ManifestRow> rows;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<std::string> c;
    std::stringstream ss(line);
    for (std::string cell; c.size() < 18 && std::getline(ss, cell, ',');) c.push_back(cell);
    ManifestRow r;
    r.file = c[0];
    r.session = c[1];
    r.survey = c[3];
    r.duration_s = std::stod(c[6]);
    r.n_uwb = std::stoul(c[8]);
    r.n_acc = std::stoul(c[9]);
    r.n_gyro = std::stoul(c[10]);
    r.n_pose = std::stoul(c[11]);
    r.n_tof = std::stoul(c[12]);
    r.n_flow = std::stoul(c[13]);
    r.n_baro = std::stoul(c[14]);
    r.neighbour_fraction = std::stod(c[15]);
    r.median_m = std::stod(c[16]);
    r.mad_m = std::stod(c[17]);
    rows.push_back(r);
  }
  return rows;
}

TEST(RealDataManifest, InspectAgreesWithManifestOnEveryPilotFlight) {
  UWB_REQUIRE_REAL_DATA(test::pilotFlight("0425-traj1"));
  const auto dir = test::realDir() / "util-pilot";
  const auto rows = readManifest(dir / "MANIFEST.csv");
  ASSERT_EQ(rows.size(), 17u);
  double max_dev_median = 0.0;
  double max_dev_mad = 0.0;
  for (const ManifestRow& row : rows) {
    SCOPED_TRACE(row.file);
    const AnchorSurvey survey = readAnchorSurvey((dir / row.survey).string());
    FlightReadOptions options;
    options.survey = &survey;
    ReadReport report;
    const Flight f = readFlightCsv((dir / row.file).string(), options, &report);
    // stream counts as listed
    EXPECT_EQ(f.tdoa.size(), row.n_uwb);
    EXPECT_EQ(f.acc.size(), row.n_acc);
    EXPECT_EQ(f.gyro.size(), row.n_gyro);
    EXPECT_EQ(f.pose.size(), row.n_pose);
    EXPECT_EQ(f.tof.size(), row.n_tof);
    EXPECT_EQ(f.flow.size(), row.n_flow);
    EXPECT_EQ(f.baro.size(), row.n_baro);
    const FlightSummary s = summarizeFlight(f, &survey, &report);
    EXPECT_NEAR(s.duration_s, row.duration_s, 0.06);
    EXPECT_NEAR(s.neighbour_pair_fraction, row.neighbour_fraction, 0.0006);
    ASSERT_TRUE(s.has_residuals);
    // The manifest's residual: all pairs, ground included; mad = mean |r − median| over |r − median| < 1 m.
    EXPECT_NEAR(s.residual.all.median_m, row.median_m, 0.005);
    EXPECT_NEAR(s.residual.all.mad_m, row.mad_m, 0.005);
    max_dev_median = std::max(max_dev_median, std::abs(s.residual.all.median_m - row.median_m));
    max_dev_mad = std::max(max_dev_mad, std::abs(s.residual.all.mad_m - row.mad_m));
    // Airborne residuals are small; the ground phase is grossly wrong (SOURCE.md caveats)
    EXPECT_LT(std::abs(s.residual.airborne.median_m), 0.05);
    EXPECT_GT(s.residual.ground.mean_abs_dev_m, s.residual.airborne.mean_abs_dev_m);
  }
  std::printf("[ manifest ] max |median − manifest| = %.4f m, max |mad − manifest| = %.4f m\n", max_dev_median,
              max_dev_mad);
}

TEST(RealDataManifest, FinalExtractResidualsMatchSourceMd) {
  const auto dir = test::realDir() / "util-final-extract";
  if (!std::filesystem::exists(dir / "const4-trial1-tdoa2-traj1.csv")) GTEST_SKIP() << "no util-final-extract";
  const AnchorSurvey survey = readAnchorSurvey((dir / "survey" / "anchor_const4_survey.txt").string());
  for (const char* name : {"const4-trial1-tdoa2-traj1.csv", "const4-trial2-tdoa2-traj3.csv"}) {
    SCOPED_TRACE(name);
    const Flight f = readFlightCsv((dir / name).string());
    const FlightSummary s = summarizeFlight(f, &survey);
    // SOURCE.md: median −0.001…+0.007 m, mean absolute deviation 0.11–0.13 m
    EXPECT_GT(s.residual.all.median_m, -0.005);
    EXPECT_LT(s.residual.all.median_m, 0.011);
    EXPECT_GT(s.residual.all.mad_m, 0.09);
    EXPECT_LT(s.residual.all.mad_m, 0.15);
    EXPECT_GT(s.neighbour_pair_fraction, 0.999) << "TDoA2 neighbour pairs, with one or two stray pairs";
  }
}

TEST(RealDataInspectCli, JsonIsExactlyOneObject) {
  const auto flight = test::pilotFlight("0425-traj4");
  UWB_REQUIRE_REAL_DATA(flight);
  UWB_REQUIRE_CLI();
  test::TempDir dir;
  const std::string out = dir.file("out.json");
  const std::string cmd = test::cliPath() + " inspect " + flight->string() + " --anchors " +
                          test::pilotSurvey("0425").string() + " --json > " + out;
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(out);
  const nlohmann::json j = nlohmann::json::parse(in);  // throws on trailing garbage
  ASSERT_TRUE(j.is_object());
  EXPECT_NEAR(j["residual"]["all"]["median_m"].get<double>(), -0.012, 0.005);
  EXPECT_EQ(j["streams"]["tdoa"]["count"].get<std::size_t>(), 11253u);
}

TEST(InspectCli, BadInputExitsNonZeroWithLocationOnStderr) {
  UWB_REQUIRE_CLI();
  test::TempDir dir;
  const std::string bad = dir.write("bad.csv", "t_tdoa,idA,idB,tdoa_meas\n0.1,1,2,oops\n");
  const std::string cmd = test::cliPath() + " inspect " + bad + " --json > " + dir.file("o") + " 2> " + dir.file("e");
  EXPECT_NE(std::system(cmd.c_str()), 0);
  std::ifstream err(dir.file("e"));
  const std::string msg((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_THAT(msg, ::testing::HasSubstr("bad.csv:2:4 (tdoa_meas)"));
  EXPECT_EQ(std::filesystem::file_size(dir.file("o")), 0u) << "nothing on stdout";
}

}  // namespace
}  // namespace uwb
