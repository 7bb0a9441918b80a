/** @file SensorRangeCliTest.cpp
 *  @brief The CLI on sensor values no sensor can give (docs/robustness.md, issue "one bad gyro sample ruins a run";
 *         docs/math/filter.md F31): one gyro_z of 1e10 or 1e308 deg/s in 0425-traj2 for `localize` and
 *         `predict-bias --inputs estimate`, five accelerometer samples of 1e30 m/s² in `stream`. Each run exits 0,
 *         writes only finite numbers, keeps the clean run's accuracy, and warns with the count of samples skipped.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/CliFixture.h"
#include "uwb/io/Airborne.h"
#include "uwb/io/PoseTrack.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;


std::vector<std::string> split(const std::string& line, char sep = ',') {
  std::vector<std::string> c;
  std::string cell;
  std::istringstream s(line);
  while (std::getline(s, cell, sep)) c.push_back(cell);
  if (!line.empty() && line.back() == sep) c.emplace_back();
  return c;
}

std::string joined(const std::vector<std::string>& c) {
  std::string s;
  for (std::size_t i = 0; i < c.size(); ++i) s += (i ? "," : "") + c[i];
  return s;
}

/// The flight CSV with the `column` cell of the first `n` samples of its stream at or after t_s set to `value` (the
/// streams are column-stacked: each has its own time column, acc/gyro in g and deg/s).
std::string spiked(const std::string& text, const std::string& time_column, const std::string& column, double t_s,
                   const std::string& value, int n = 1) {
  std::istringstream in(text);
  std::string out, line;
  std::getline(in, line);
  const std::vector<std::string> header = split(line);
  out += line + '\n';
  const auto index = [&](const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    throw std::runtime_error("no column " + name);
  };
  const std::size_t it = index(time_column), ic = index(column);
  while (std::getline(in, line)) {
    std::vector<std::string> c = split(line);
    if (n > 0 && c.size() > ic && !c[it].empty() && std::stod(c[it]) >= t_s) {
      c[ic] = value;
      line = joined(c);
      --n;
    }
    out += line + '\n';
  }
  return out;
}

class SensorRangeCli : public test::PilotFlightCliTest {
 protected:
  SensorRangeCli() : PilotFlightCliTest("0425-traj2") {}
  void SetUp() override {
    PilotFlightCliTest::SetUp();
    if (IsSkipped()) return;
    text_ = test::readFileBytes(*flight_);
  }
  /// `localize --json --no-diagnostics` on a flight file: exit code, summary, trajectory text, stderr.
  struct Run {
    int exit_code = -1;
    nlohmann::json j;
    std::string trajectory, err;
  };
  Run localize(const std::string& flight) const {
    const std::string out = path("trajectory.csv");
    fs::remove(out);
    const test::CliResult r =
        test::runCli("localize " + flight + " --anchors " + survey_ + " --json --no-diagnostics --out " + out);
    Run run{r.exit_code, nullptr, fs::exists(out) ? test::readFileBytes(out) : std::string(), r.err};
    if (r.exit_code == 0) run.j = nlohmann::json::parse(r.out);
    return run;
  }

  std::string text_;
};

TEST_F(SensorRangeCli, OneGyroSampleOfHugeRateIsSkippedCountedAndWarned) {
  const Run clean = localize(flight_->string());
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  EXPECT_EQ(clean.j["sensor_range"]["gyro"]["n"], 0) << "the check fired on the clean flight";
  EXPECT_THAT(clean.err, Not(HasSubstr("physical range")));
  for (const std::string value : {"1e10", "1e308"}) {
    SCOPED_TRACE(value);
    // GIVEN 0425-traj2 with one gyro_z of 1e10 deg/s (or 1e308) at t = 20 s, in flight
    const std::string f = write("gyro_" + value + ".csv", spiked(text_, "t_gyro", "gyro_z", 20.0, value));
    // WHEN it is localized
    const Run r = localize(f);
    // THEN the run succeeds (1e308 used to end in a NaN estimate), every number written is finite, the accuracy is
    // the clean run's (1e10 used to raise the RMSE 0.165 → 0.215 m), and one gyro sample is reported skipped
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_THAT(r.trajectory, Not(HasSubstr("nan")));
    EXPECT_THAT(r.trajectory, Not(HasSubstr("inf")));
    EXPECT_LE(r.j["rmse_m"].get<double>(), 1.05 * clean.j["rmse_m"].get<double>());
    EXPECT_LE(r.j["rmse_airborne_m"].get<double>(), 1.05 * clean.j["rmse_airborne_m"].get<double>());
    EXPECT_EQ(r.j["sensor_range"]["gyro"]["n"], 1);
    EXPECT_NEAR(r.j["sensor_range"]["gyro"]["first_t_s"].get<double>(), 20.0, 0.01);
    EXPECT_THAT(r.err, HasSubstr("skipped 1 gyro sample outside the sensor's physical range"));
  }
}

TEST_F(SensorRangeCli, PredictBiasOnEstimatedInputsWritesNoNanRowForOneBadGyroSample) {
  // GIVEN a small bias model trained on 0425-traj2 and the flight with one gyro_z of 1e308 deg/s at t = 20 s
  const std::string model = path("model.json");
  const test::CliResult t = test::runCli("train " + flight_->string() + " --anchors " + survey_ +
                                         " --kernel tdoa --inducing 5 --epochs 2 --quiet --out " + model);
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const std::string f = write("gyro.csv", spiked(text_, "t_gyro", "gyro_z", 20.0, "1e308"));
  const auto predict = [&](const std::string& flight, const std::string& out) {
    return test::runCli("predict-bias " + flight + " --anchors " + survey_ + " --model " + model +
                        " --inputs estimate --json --out " + out);
  };
  const std::string out_clean = path("clean.csv"), out = path("bias.csv");
  const test::CliResult c = predict(flight_->string(), out_clean);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  // WHEN the bias is predicted on the filter's estimate
  const test::CliResult r = predict(f, out);
  // THEN it succeeds (it used to write 7 205 of 7 214 rows NaN), with as many rows as on the clean flight and no NaN
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json jc = nlohmann::json::parse(c.out), j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["n_rows"].get<double>(), jc["n_rows"].get<double>(), 0.02 * jc["n_rows"].get<double>());
  const std::string rows = test::readFileBytes(out);
  EXPECT_THAT(rows, Not(HasSubstr("nan")));
  EXPECT_THAT(rows, Not(HasSubstr("inf")));
  EXPECT_LE(j["bias_rmse_before_m"].get<double>(), 1.05 * jc["bias_rmse_before_m"].get<double>());
  EXPECT_THAT(r.err, HasSubstr("skipped 1 gyro sample outside the sensor's physical range"));
}

/// RMS of the streamed positions against the flight's ground truth, over the samples with the truth airborne.
double airborneRmse(const std::string& csv, const PoseTrack& truth) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  double se = 0.0;
  std::size_t n = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> c = split(line);
    const std::optional<PoseSample> p = truth.interpolate(std::stod(c[0]));
    if (!p || !isAirborne(p->w_p_b.z())) continue;
    se += (Vec3(std::stod(c[1]), std::stod(c[2]), std::stod(c[3])) - p->w_p_b).squaredNorm();
    ++n;
  }
  return n ? std::sqrt(se / static_cast<double>(n)) : std::nan("");
}

TEST_F(SensorRangeCli, StreamSkipsFiveAccelerometerSamplesOfHugeForce) {
  // GIVEN the events of 0425-traj2 in the line protocol, and the same with five accelerometer samples of 1e30 m/s²
  // at t = 20 s (in flight)
  const test::CliResult replay = test::runCli("replay " + flight_->string());
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  std::istringstream in(replay.out);
  std::string clean, faulty, line;
  int n_spiked = 0;
  while (std::getline(in, line)) {
    clean += line + '\n';
    if (n_spiked < 5 && line.rfind("imu,", 0) == 0) {
      std::vector<std::string> c = split(line);
      if (std::stod(c[1]) >= 20.0) {
        c[4] = "1e30";  // imu,t,ax,ay,az,gx,gy,gz
        line = joined(c);
        ++n_spiked;
      }
    }
    faulty += line + '\n';
  }
  ASSERT_EQ(n_spiked, 5);
  const auto stream = [&](const std::string& events) {
    return test::runCli("stream --anchors " + survey_ + " --format csv < " + write("events.txt", events));
  };
  const test::CliResult c = stream(clean);
  // WHEN they are streamed
  const test::CliResult r = stream(faulty);
  // THEN the estimate keeps the clean run's accuracy in the air (it used to be 1.55 m, with the phase "landed" in
  // flight), and the five samples are reported skipped
  ASSERT_EQ(c.exit_code, 0) << c.err;
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const PoseTrack truth(readFlightCsv(flight_->string()));
  const double rmse_clean = airborneRmse(c.out, truth), rmse = airborneRmse(r.out, truth);
  ASSERT_TRUE(std::isfinite(rmse_clean));
  EXPECT_LE(rmse, 1.05 * rmse_clean) << "clean " << rmse_clean;
  EXPECT_THAT(r.err, HasSubstr("skipped 5 accelerometer samples outside the sensor's physical range"));
  EXPECT_THAT(c.err, Not(HasSubstr("physical range")));
}

TEST_F(SensorRangeCli, TheGrossTdoaOutliersOfARealFlightAreSkippedAndNamed) {
  // GIVEN 0426-traj11, whose log carries 16 TDoA 17–25 m beyond their anchor pair's baseline
  const std::optional<fs::path> f = test::pilotFlight("0426-traj11");
  UWB_REQUIRE_REAL_DATA(f);
  // WHEN it is localized
  const test::CliResult r = test::runCli("localize " + f->string() + " --anchors " +
                                         test::pilotSurvey("0426").string() + " --json --no-diagnostics");
  // THEN they are skipped and named in one warning, and nothing else of the flight is (IMU within its range)
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["sensor_range"]["tdoa"]["n"], 16);
  EXPECT_GT(j["sensor_range"]["tdoa"]["worst"].get<double>(), 10.0);
  EXPECT_EQ(j["sensor_range"]["gyro"]["n"], 0);
  EXPECT_EQ(j["sensor_range"]["acc"]["n"], 0);
  EXPECT_THAT(r.err,
              HasSubstr("skipped 16 TDoA outside the sensor's physical range (|z| ≤ anchor-pair baseline + 1 m"));
}

}  // namespace
}  // namespace uwb
