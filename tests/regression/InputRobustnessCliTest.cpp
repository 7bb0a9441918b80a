/** @file InputRobustnessCliTest.cpp
 *  @brief The CLI on bad or crafted input (docs/robustness.md): every case ends in a clear error naming the file
 *         and the field, or in a warning that `--json` reports; a failing command leaves no output file. The inputs
 *         are tiny files the tests write themselves, from a short simulated flight.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <fmt/format.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "support/CliFixture.h"
#include "uwb/eval/BiasCalibration.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

/// A 30 s simulated flight, its survey and a tiny trained bias model, shared by the tests of this file.
class RobustCli : public test::SimulatedCircleSuite<RobustCli> {
 protected:
  static std::string localizeArgs(const std::string& flight, const std::string& survey) {
    return "localize " + flight + " --anchors " + survey + " --json";
  }
  /// The trained model (made once: 2 epochs, 5 inducing points on the simulated flight).
  static const std::string& model() {
    static std::string path;
    if (path.empty()) {
      path = (dir_ / "model.json").string();
      const test::CliResult r = test::runCli("train " + flight_ + " --anchors " + survey_ +
                                             " --kernel tdoa --inducing 5 --epochs 2 --quiet --json --out " + path);
      EXPECT_EQ(r.exit_code, 0) << r.err;
    }
    return path;
  }
  /// Expects a non-zero exit, empty stdout and stderr containing every part.
  static void expectFailure(const test::CliResult& r, int exit_code, const std::vector<std::string>& parts) {
    EXPECT_EQ(r.exit_code, exit_code) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    for (const auto& p : parts) EXPECT_THAT(r.err, HasSubstr(p));
    EXPECT_THAT(r.err, Not(HasSubstr("bad_alloc")));
    EXPECT_THAT(r.err, Not(HasSubstr("json.exception")));
  }

};

// ----------------------------------------------------------------------------------------------- crashes, blow-ups

TEST_F(RobustCli, InspectOfAHugeAnchorIdIsALineErrorNotGigabytes) {
  // GIVEN the two-line CSV that made `inspect` allocate a table of 2^31 ids until it was killed
  const std::string csv = write("huge_id.csv", "t_tdoa,idA,idB,tdoa_meas\n0.1,2147483647,0,0.5\n");
  // THEN the reader names the line and the field
  expectFailure(test::runCli("inspect " + csv + " --json"), 2, {"huge_id.csv:2:2 (idA)", "[0, 255]"});
}

TEST_F(RobustCli, DirectoriesAndDevicesAreRefusedAsEveryInput) {
  const std::string d = dir_.string();
  expectFailure(test::runCli("inspect " + d), 3, {"is a directory"});
  expectFailure(test::runCli(localizeArgs(d, survey_)), 3, {"flight file", "is a directory"});
  expectFailure(test::runCli(localizeArgs(flight_, d)), 3, {"anchor survey", "is a directory"});
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --config " + d), 3, {"config file", "is a directory"});
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --bias-model " + d), 3,
                {"bias model", "is a directory"});
  if (fs::exists("/dev/zero")) expectFailure(test::runCli("inspect /dev/zero"), 3, {"character device"});
}

TEST_F(RobustCli, SimulateRefusesAnAbsurdDurationBeforeAllocating) {
  const std::string out = (dir_ / "long.csv").string(), sout = (dir_ / "long.txt").string();
  for (const char* d : {"1e7", "0", "-5", "nan"}) {
    SCOPED_TRACE(d);
    const test::CliResult r =
        test::runCli(std::string("simulate --duration ") + d + " --json --out " + out + " --survey-out " + sout);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.err, Not(HasSubstr("bad_alloc")));
  }
  const test::CliResult r = test::runCli("simulate --duration 1e7 --out " + out + " --survey-out " + sout);
  EXPECT_THAT(r.err, HasSubstr("--duration"));
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(sout));
}

// ----------------------------------------------------------------------------------- geometry, units, CLI values

TEST_F(RobustCli, ASurveyWithAllAnchorsAtOnePointIsAnError) {
  // GIVEN the survey's ids, every anchor at the same point (localize used to answer with a 145 m RMSE, rc 0)
  std::istringstream lines(test::readFileBytes(survey_));
  std::string text;
  for (std::string line; std::getline(lines, line);) {
    const auto comma = line.find(',');
    if (line.find("_p,") != std::string::npos) text += line.substr(0, comma) + ",1,2,1.5\n";
  }
  const std::string point = write("point_survey.txt", text);
  expectFailure(test::runCli(localizeArgs(flight_, point)), 2, {"point_survey.txt", "one point"});
}

TEST_F(RobustCli, ImuStampsInMillisecondsAreAnErrorNamingTheColumn) {
  // GIVEN the flight with its IMU stamps written in milliseconds (used to run with 0 TDoA used, rc 0)
  Flight f = readFlightCsv(flight_);
  for (auto& s : f.acc) s.t_s *= 1000.0;
  for (auto& s : f.gyro) s.t_s *= 1000.0;
  const std::string ms = (dir_ / "imu_ms.csv").string();
  writeFlightCsv(f, ms);
  expectFailure(test::runCli(localizeArgs(ms, survey_)), 2, {"imu_ms.csv", "t_acc", "milliseconds"});
  // AND inspect reports it as a warning (a diagnostic tool does not stop)
  const test::CliResult r = test::runCli("inspect " + ms + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(nlohmann::json::parse(r.out)["warnings"].dump(), HasSubstr("t_acc"));
}

TEST_F(RobustCli, ProcessModelImuOnAFlightWithoutImuIsAnErrorAndTheDefaultSaysSo) {
  Flight f = readFlightCsv(flight_);
  f.acc.clear();
  f.gyro.clear();
  std::vector<std::string> columns;
  for (const auto& c : f.columns) {
    if (c.rfind("acc", 0) != 0 && c.rfind("gyro", 0) != 0 && c != "t_acc" && c != "t_gyro") columns.push_back(c);
  }
  f.columns = columns;
  const std::string no_imu = (dir_ / "no_imu.csv").string();
  writeFlightCsv(f, no_imu);
  // WHEN the IMU model is asked for explicitly THEN it is an error (it used to fall back to cv silently)
  expectFailure(test::runCli(localizeArgs(no_imu, survey_) + " --process-model imu"), 2, {"no IMU"});
  // WHEN nothing is asked THEN the TDoA-only model runs (the documented default) and --json says so
  const test::CliResult r = test::runCli(localizeArgs(no_imu, survey_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_NE(j["process_model"], "imu");
  EXPECT_THAT(j["notes"].dump(), HasSubstr("no IMU"));
}

TEST_F(RobustCli, ImplausibleCommandLineValuesAreRefusedWithTheOptionName) {
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --start 1e6,0,0"), 2, {"--start", "outside the anchors"});
  for (const char* period : {"0", "-1", "nan", "1e9"}) {
    SCOPED_TRACE(period);
    const test::CliResult r = test::runCli(localizeArgs(flight_, survey_) + " --output-period " + period);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_THAT(r.err, HasSubstr("output-period"));
    EXPECT_TRUE(r.out.empty());
  }
}

TEST_F(RobustCli, ConfigErrorsNameTheFileAndTheKey) {
  const std::string huge = write("huge.json", R"({"robust_iterations": 1e300})");
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --config " + huge), 2,
                {"huge.json (robust_iterations)", "must be in [1, 20]"});
  const std::string type = write("type.json", R"({"robust_loss": 3})");
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --config " + type), 2,
                {"type.json (robust_loss)", "must be one of"});
  const std::string syntax = write("syntax.json", "{\n  \"gate_sigma\": 3,,\n}\n");
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --config " + syntax), 2, {"syntax.json:2:", "invalid JSON"});
  const std::string range = write("range.json", R"({"tdoa_sigma_m": -1})");
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --config " + range), 2, {"range.json", "tdoa_sigma_m"});
  const std::string sim = write("sim.json", R"({"bias": {"multipath_features": 1e300}})");
  expectFailure(test::runCli("simulate --config " + sim + " --out " + (dir_ / "x.csv").string() + " --survey-out " +
                             (dir_ / "x.txt").string()),
                2, {"sim.json (bias.multipath_features)", "must be an integer"});
  const auto simulateWith = [&](const std::string& config) {
    return test::runCli("simulate --config " + config + " --out " + (dir_ / "x.csv").string() + " --survey-out " +
                        (dir_ / "x.txt").string());
  };
  expectFailure(simulateWith(write("drag.json", R"({"rotor_drag_per_s": "fast"})")), 2,
                {"drag.json (rotor_drag_per_s)", "must be a number"});
  // a value of the right type out of its range: the parameters' own check, with the file and the section
  expectFailure(simulateWith(write("drag.json", R"({"rotor_drag_per_s": -0.1})")), 2,
                {"drag.json", "rotor_drag_per_s must be in [0, 10)"});
  expectFailure(simulateWith(write("imu.json", R"({"imu": {"rate_hz": 5}})")), 2,
                {"imu.json (imu)", "imu.rate_hz must be in [10, 10000]"});
  expectFailure(simulateWith(write("path.json", R"({"trajectory": {"radius_m": -1}})")), 2,
                {"path.json (trajectory)", "radius_m > 0"});
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.csv"));
}

// ------------------------------------------------------------------------------------------------ bias models

TEST_F(RobustCli, CorruptBiasModelValuesAreErrorsNamingTheFileAndKey) {
  const nlohmann::json good = nlohmann::json::parse(test::readFileBytes(model()));
  ASSERT_TRUE(good.contains("models"));
  struct Case {
    const char* name;
    std::function<void(nlohmann::json&)> corrupt;
    const char* key;
  };
  const std::vector<Case> cases{
      {"version", [](nlohmann::json& j) { j["version"] = 1e300; }, "version"},
      {"id_a", [](nlohmann::json& j) { j["models"][0]["id_a"] = 1e300; }, "models[0].id_a"},
      {"mean", [](nlohmann::json& j) { j["pair_means"] = {{{"id_a", 0}, {"id_b", 1}, {"mean_m", 1e6}}}; },
       "pair_means[0].mean_m"},
      {"jitter", [](nlohmann::json& j) { j["models"][0]["svgp"]["jitter"] = -10; }, "models[0].svgp.jitter"},
      {"dof", [](nlohmann::json& j) { j["predictive_dof"] = 1.0; }, "predictive_dof"},
      {"scale", [](nlohmann::json& j) { j["predictive_scale"] = "wide"; }, "predictive_scale"},
      {"level", [](nlohmann::json& j) { j["training_bias_level_m"] = -0.2; }, "training_bias_level_m"},
      {"dims", [](nlohmann::json& j) { j["models"][0]["svgp"]["kernel"]["parts"][0]["active_dims"] = {1e300}; },
       "active_dims"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    nlohmann::json bad = good;
    c.corrupt(bad);
    const std::string path = write(std::string("bad_") + c.name + ".json", bad.dump());
    const std::string out = (dir_ / "never.csv").string();
    expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --bias-model " + path + " --out " + out), 2,
                  {std::string("bad_") + c.name + ".json", c.key});
    EXPECT_FALSE(fs::exists(out));  // a failing command leaves no output
  }
}

TEST_F(RobustCli, PredictBiasWritesTheMeasuredTdoaAndThePredictiveDistributionInEveryRow) {
  // The measured TDoA of the flight by (time, pair), as the CSV prints it (6 decimals of time, 7 digits of TDoA).
  const Flight f = readFlightCsv(flight_);
  std::map<std::string, double> measured;
  for (const auto& m : f.tdoa) measured[fmt::format("{:.6f},{},{}", m.t_s, m.id_a, m.id_b)] = m.tdoa_m;
  for (const char* inputs : {"truth", "estimate"}) {
    SCOPED_TRACE(inputs);
    const std::string out = (dir_ / (std::string("pred_") + inputs + ".csv")).string();
    const test::CliResult r = test::runCli("predict-bias " + flight_ + " --anchors " + survey_ + " --model " + model() +
                                           " --inputs " + inputs + " --json --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::istringstream lines(test::readFileBytes(out));
    std::string line;
    std::getline(lines, line);
    ASSERT_EQ(line, "t,idA,idB,tdoa_meas,error_m,bias_mean_m,bias_std_m,airborne,predictive_std_m");
    std::size_t rows = 0;
    // the summary's calibration (P43) recomputed from the rows: airborne, |ε| ≤ 1 m, r = ε − µ against the
    // predictive std (the std of the mean plus the likelihood noise, so never below the std of the mean) and the
    // central intervals of the model's predictive shape (P43b)
    const BiasModel bias_model = BiasModel::load(model());
    const double w1 = centralIntervalHalfWidth(kOneSigmaMass, bias_model.predictiveShape());
    const double w2 = centralIntervalHalfWidth(kTwoSigmaMass, bias_model.predictiveShape());
    std::size_t n_scored = 0, in1 = 0, in2 = 0;
    while (std::getline(lines, line)) {
      std::vector<std::string> cells;
      std::stringstream ss(line);
      for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
      ASSERT_EQ(cells.size(), 9u) << line;
      ASSERT_FALSE(cells[3].empty()) << "empty tdoa_meas: " << line;
      const double eps = std::stod(cells[4]), mu = std::stod(cells[5]), sd_mean = std::stod(cells[6]),
                   sd = std::stod(cells[8]);
      EXPECT_GE(sd, sd_mean) << line;
      if (cells[7] == "1" && std::abs(eps) <= 1.0 && sd > 0.0) {
        ++n_scored;
        in1 += std::abs(eps - mu) <= w1 * sd ? 1 : 0;
        in2 += std::abs(eps - mu) <= w2 * sd ? 1 : 0;
      }
      const auto it = measured.find(cells[0] + "," + cells[1] + "," + cells[2]);
      ASSERT_NE(it, measured.end()) << line;
      EXPECT_NEAR(std::stod(cells[3]), it->second, 1e-6 * std::max(1.0, std::abs(it->second))) << line;
      ++rows;
    }
    EXPECT_GT(rows, 1000u);
    const nlohmann::json summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(summary["n_rows"].get<std::size_t>(), rows);
    const nlohmann::json& cal = summary["calibration"];
    ASSERT_GT(n_scored, 100u);
    EXPECT_EQ(cal["n"].get<std::size_t>(), n_scored);
    // the CSV's 7 significant digits can move a sample across an interval's edge
    EXPECT_NEAR(cal["coverage_1sigma"].get<double>(), static_cast<double>(in1) / n_scored, 2e-3);
    EXPECT_NEAR(cal["coverage_2sigma"].get<double>(), static_cast<double>(in2) / n_scored, 2e-3);
    EXPECT_LT(cal["coverage_1sigma"].get<double>(), cal["coverage_2sigma"].get<double>());
    EXPECT_TRUE(std::isfinite(cal["nlpd"].get<double>()));
    EXPECT_EQ(cal["predictive_dof"].get<double>(), bias_model.predictiveShape().dof);
  }
}

// ------------------------------------------------------------------------------------------------ outputs

TEST_F(RobustCli, UnwritableOutputsFailBeforeTheWork) {
  const std::string missing = (dir_ / "no_such_folder" / "out").string();
  expectFailure(test::runCli(localizeArgs(flight_, survey_) + " --out " + missing + ".csv"), 3, {"no_such_folder"});
  expectFailure(test::runCli("train " + flight_ + " --anchors " + survey_ + " --quiet --out " + missing + ".json"), 3,
                {"bias model", "no_such_folder"});
  expectFailure(test::runCli("predict-bias " + flight_ + " --anchors " + survey_ + " --model " + model() +
                             " --out " + missing + ".csv"),
                3, {"no_such_folder"});
  expectFailure(test::runCli("simulate --out " + missing + ".csv --survey-out " + (dir_ / "s2.txt").string()), 3,
                {"no_such_folder"});
  const std::string file = write("plain_file", "x");
  expectFailure(test::runCli("evaluate --train " + flight_ + " --test " + flight_ + " --anchors " + survey_ +
                             " --no-plots --out " + file + "/report"),
                3, {"report folder", "not a folder"});
  EXPECT_FALSE(fs::exists(dir_ / "s2.txt"));
  EXPECT_FALSE(fs::exists(dir_ / "no_such_folder"));
}

TEST_F(RobustCli, AFileNameThatIsNotUtf8StillGivesJsonAndAFile) {
  // GIVEN an output name with a byte that is not UTF-8 (the JSON printer used to throw after --out was written)
  const std::string out = (dir_ / "traj_\xff.csv").string();
  const test::CliResult r = test::runCli(localizeArgs(flight_, survey_) + " --out '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out).is_object());
  EXPECT_TRUE(fs::exists(out));
  // AND no temporary file is left beside it
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_THAT(e.path().filename().string(), Not(HasSubstr(".tmp-")));
}

}  // namespace
}  // namespace uwb
