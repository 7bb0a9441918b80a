/** @file StreamRobustnessCliTest.cpp
 *  @brief `uwbtdoa stream` on the faults of live operation (docs/robustness.md): one stamp far ahead, a clock that
 *         restarts at 0, malformed lines and anchors outside the survey, a ZeroMQ producer that is killed. The run
 *         goes on (skip, count, warn; the estimator starts again after a clock jump) instead of stopping its
 *         estimates or waiting forever. The events are those of a short simulated flight replayed to text.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/wait.h>

#include "support/CliFixture.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::ContainsRegex;

/// A 30 s simulated circle, its survey and its events in the line protocol, shared by the tests of this file.
class StreamFaults : public test::SimulatedCircleSuite<StreamFaults> {
 protected:
  static void SetUpTestSuite() {
    SimulatedCircleSuite::SetUpTestSuite();
    if (dir_.empty() || HasFatalFailure()) return;
    const test::CliResult replay = test::runCli("replay " + flight_);
    ASSERT_EQ(replay.exit_code, 0) << replay.err;
    std::istringstream in(replay.out);
    for (std::string line; std::getline(in, line);) events_.push_back(line);
    ASSERT_GT(events_.size(), 10000u);
  }

  /// The stamp of an event line (its second field).
  static double stampOf(const std::string& line) {
    const std::size_t c = line.find(',');
    return std::stod(line.substr(c + 1, line.find(',', c + 1) - c - 1));
  }
  static std::string withStamp(const std::string& line, double t_s) {
    const std::size_t c = line.find(','), d = line.find(',', c + 1);
    std::ostringstream s;
    s.precision(17);
    s << line.substr(0, c + 1) << t_s << line.substr(d);
    return s.str();
  }
  /// Index of the first event line at or after t_s.
  static std::size_t indexAt(double t_s) {
    for (std::size_t i = 0; i < events_.size(); ++i)
      if (events_[i][0] != '#' && stampOf(events_[i]) >= t_s) return i;
    return events_.size();
  }
  static std::string write(const std::string& name, const std::vector<std::string>& lines) {
    const fs::path p = dir_ / name;
    std::ofstream out(p);
    for (const std::string& l : lines) out << l << '\n';
    return p.string();
  }
  /// `stream --format csv` on a file of events; the estimates' stamps.
  static test::CliResult stream(const std::string& events, const std::string& flags, std::vector<double>* t_out) {
    const test::CliResult r =
        test::runCli("stream --anchors " + survey_ + " --format csv " + flags + " < " + events);
    std::istringstream in(r.out);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) t_out->push_back(std::stod(line.substr(0, line.find(','))));
    return r;
  }
  static std::size_t countOf(const std::string& err, const std::string& what) {
    std::smatch m;
    if (!std::regex_search(err, m, std::regex("([0-9]+) " + what))) return static_cast<std::size_t>(-1);
    return std::stoul(m[1]);
  }

  static inline std::vector<std::string> events_;
};

TEST_F(StreamFaults, OneImuStampFarAheadCostsOneEventNotTheRestOfTheFlight) {
  // GIVEN the flight's events with one IMU stamp of 1e12 s at 12 s
  std::vector<std::string> lines = events_;
  std::size_t k = indexAt(12.0);
  while (lines[k].rfind("imu,", 0) != 0) ++k;
  lines[k] = withStamp(lines[k], 1e12);
  std::vector<double> t_clean, t_fault;
  const test::CliResult clean = stream(write("clean.txt", events_), "", &t_clean);
  // WHEN it is streamed
  const test::CliResult r = stream(write("ahead.txt", lines), "", &t_fault);
  // THEN the estimates go on to the end of the flight (they used to stop at 12 s), one event was skipped and counted
  // with a warning naming the stamp
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_FALSE(t_fault.empty());
  EXPECT_GT(t_fault.back(), 29.0) << r.err;
  EXPECT_NEAR(static_cast<double>(t_fault.size()), static_cast<double>(t_clean.size()), 2.0);
  for (double t : t_fault) EXPECT_LT(t, 100.0);
  EXPECT_THAT(r.err, HasSubstr("off the sensor clock"));
  EXPECT_THAT(r.err, HasSubstr("1e+12 s"));
  EXPECT_EQ(countOf(r.err, "events off the clock skipped"), 1u) << r.err;
}

TEST_F(StreamFaults, AClockThatRestartsAtZeroIsWarnedAndTheEstimatorStartsAgain) {
  // GIVEN the flight's events whose clock restarts at 0 at 15 s (a reboot in the air)
  std::vector<std::string> lines = events_;
  const std::size_t k = indexAt(15.0);
  for (std::size_t i = k; i < lines.size(); ++i)
    if (lines[i][0] != '#') lines[i] = withStamp(lines[i], stampOf(lines[i]) - 15.0);
  std::vector<double> t_out;
  // WHEN it is streamed
  const test::CliResult r = stream(write("reboot.txt", lines), "", &t_out);
  // THEN a loud warning names the jump, the estimator starts again, and estimates come on the new clock to the end
  // (they used to stop at 15 s)
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, ContainsRegex("THE SENSOR CLOCK JUMPED from 1[45]\\.[0-9]+ s to 0 s"));
  EXPECT_EQ(countOf(r.err, "clock jumps"), 1u) << r.err;
  std::size_t after = 0;
  for (std::size_t i = 1; i < t_out.size(); ++i)
    if (t_out[i] < t_out[i - 1] - 5.0) after = t_out.size() - i;
  EXPECT_GT(after, 500u) << r.err;  // 15 s on the new clock at 100 Hz, less the new start
  ASSERT_FALSE(t_out.empty());
  EXPECT_GT(t_out.back(), 14.0);
  EXPECT_LT(t_out.back(), 15.5);
}

TEST_F(StreamFaults, AMalformedLineIsSkippedCountedAndReportedUnlessStrict) {
  // GIVEN the flight's events with a malformed line at 10 s
  std::vector<std::string> lines = events_;
  const std::size_t k = indexAt(10.0);
  lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(k), "tdoa,10.0,0,1,zz");
  const std::string path = write("malformed.txt", lines);
  // WHEN it is streamed without and with --strict
  std::vector<double> t_out, t_strict;
  const test::CliResult r = stream(path, "", &t_out);
  const test::CliResult strict = stream(path, "--strict", &t_strict);
  // THEN the line is skipped with a warning naming its line and reason, the estimates go on to the end, the total is
  // printed; with --strict it stops with the located error (exit 2), as it did by default before
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("<stdin>:" + std::to_string(k + 1) + ":"));
  EXPECT_THAT(r.err, HasSubstr("'zz' is not a number; line skipped"));
  EXPECT_EQ(countOf(r.err, "bad lines skipped"), 1u) << r.err;
  ASSERT_FALSE(t_out.empty());
  EXPECT_GT(t_out.back(), 29.0);
  EXPECT_EQ(strict.exit_code, 2);
  EXPECT_THAT(strict.err, HasSubstr("<stdin>:" + std::to_string(k + 1) + ":"));
}

TEST_F(StreamFaults, AnchorsOutsideTheSurveyAndEqualIdsAreRefusedPerLine) {
  // GIVEN TDoA lines naming anchor 99 (not in the survey), -1, 300, and an anchor paired with itself
  const std::vector<std::string> bad = {"tdoa,8.0,99,1,0.5", "tdoa,8.0,-1,1,0.5", "tdoa,8.0,0,300,0.5",
                                        "tdoa,8.0,2,2,0.0"};
  std::vector<std::string> lines = events_;
  lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(indexAt(8.0)), bad.begin(), bad.end());
  const std::string path = write("anchors.txt", lines);
  std::vector<double> t_out;
  const test::CliResult r = stream(path, "", &t_out);
  // THEN each is skipped and counted with its reason; --strict stops at the first
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(countOf(r.err, "bad lines skipped"), 4u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("anchor 99 is not in the survey"));
  EXPECT_THAT(r.err, HasSubstr("anchor id -1 is outside [0, 255]"));
  EXPECT_THAT(r.err, HasSubstr("anchor id 300 is outside [0, 255]"));
  EXPECT_THAT(r.err, HasSubstr("id_a and id_b are both 2"));
  for (const char* s : {"tdoa,8.0,99,1,0.5", "tdoa,8.0,2,2,0.0"}) {
    std::vector<double> t_strict;
    const test::CliResult strict = stream(write("one.txt", {"# uwbtdoa-events v1", s}), "--strict", &t_strict);
    EXPECT_EQ(strict.exit_code, 2) << s;
    EXPECT_THAT(strict.err, ContainsRegex("<stdin>:2[: ]")) << s;
  }
}

TEST_F(StreamFaults, ManyBadLinesPrintTenWarningsAndTheTotal) {
  // GIVEN 25 malformed lines
  std::vector<std::string> lines = events_;
  lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(indexAt(5.0)), 25, "imu,5.0,1,2");
  std::vector<double> t_out;
  const test::CliResult r = stream(write("many.txt", lines), "", &t_out);
  // THEN ten are reported one by one, all 25 are counted
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::size_t n_reported = 0;
  for (std::size_t at = r.err.find("line skipped"); at != std::string::npos; at = r.err.find("line skipped", at + 1))
    ++n_reported;
  EXPECT_EQ(n_reported, 10u) << r.err;
  EXPECT_EQ(countOf(r.err, "bad lines skipped"), 25u) << r.err;
}

TEST_F(StreamFaults, AKilledZmqProducerEndsTheStreamAfterTheIdleTimeout) {
  // GIVEN a paced replay into ZeroMQ that is killed (SIGKILL) after 6 s, and `stream --in` on it with a 2 s idle
  // timeout
  const std::string in = "tcp://127.0.0.1:" + std::to_string(40000 + (::getpid() * 2 + 1) % 20000);
  const fs::path out = dir_ / "zmq.out", err = dir_ / "zmq.err";
  auto producer = std::async(std::launch::async, [&] {
    const std::string cmd = "timeout -s KILL 6 " + test::cliPath() + " replay " + flight_ + " --speed 1 --to " + in +
                            " 2>/dev/null";
    return std::system(cmd.c_str());
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the producer binds and waits for a subscriber
  const auto t0 = std::chrono::steady_clock::now();
  const std::string cmd = "timeout 40 " + test::cliPath() + " stream --anchors " + survey_ + " --in " + in +
                          " --idle-timeout 2 >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int p_status = producer.get();
  // WHEN the producer is gone
  std::ifstream e(err);
  const std::string stderr_text{std::istreambuf_iterator<char>(e), std::istreambuf_iterator<char>()};
  // THEN the stream ends by itself (exit 0, not the 40 s guard's 124) with a warning and its summary
  EXPECT_NE(WIFEXITED(p_status) ? WEXITSTATUS(p_status) : -1, 0);  // the producer was killed
  EXPECT_EQ(code, 0) << stderr_text;
  EXPECT_LT(wall_s, 20.0);
  EXPECT_THAT(stderr_text, HasSubstr("no message for 2 s (--idle-timeout)"));
  EXPECT_THAT(stderr_text, HasSubstr("(idle timeout)"));
  EXPECT_NE(countOf(stderr_text, "events"), static_cast<std::size_t>(-1)) << stderr_text;  // the summary
}

}  // namespace
}  // namespace uwb
