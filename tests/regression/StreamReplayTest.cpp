/** @file StreamReplayTest.cpp
 *  @brief `uwbtdoa replay | uwbtdoa stream` on 5 s of a real flight gives the batch path's estimates
 *         (TdoaLocalizer::run on the same events) to 1e-9 m; a malformed line is a located error; `--speed 1` paces
 *         in real time; SIGINT ends the stream cleanly with its output flushed.
 */
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include "support/CliFixture.h"
#include "uwb/eval/Localization.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/stream/EstimateFormat.h"

namespace uwb {
namespace {

/// 5 s of a flight in the air (12–17 s), as a log started in flight would hold them.
class StreamCli : public test::PilotFlightCliTest {
 protected:
  StreamCli() : PilotFlightCliTest("0425-traj1", {{12.0, 17.0}}) {}
};

std::vector<LocalizerEstimate> parseLines(const std::string& text, EstimateFormat f, bool header) {
  std::vector<LocalizerEstimate> out;
  std::istringstream in(text);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);)
    if (n++ > 0 || !header) out.push_back(parseEstimate(line, f, n));
  return out;
}

TEST_F(StreamCli, ReplayIntoStreamGivesTheBatchEstimates) {
  for (const char* format : {"json", "csv", "tum"}) {
    // GIVEN 5 s of a real flight, replayed at full speed into `stream`
    const test::CliResult r = test::runCli("replay " + short_ + " --speed max | " + test::cliPath() +
                                           " stream --anchors " + survey_ + " --output-period 0.01 --format " + format);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string format_name = format;
    const EstimateFormat f = format_name == "csv"   ? EstimateFormat::kCsv
                             : format_name == "tum" ? EstimateFormat::kTum
                                                    : EstimateFormat::kJson;
    const std::vector<LocalizerEstimate> streamed = parseLines(r.out, f, f != EstimateFormat::kJson);
    // WHEN the batch path runs on the same flight's events
    const EkfParams p;
    const LocalizerResult batch =
        TdoaLocalizer(p, anchorTableFromSurvey(readAnchorSurvey(survey_), p.anchor_sigma_m))
            .run(replayLogFromFlight(readFlightCsv(short_)), 0.01);
    // THEN the same estimates: one per 10 ms once the position is known, positions within 1e-9 m
    ASSERT_GT(batch.estimates.size(), 400u);
    ASSERT_EQ(streamed.size(), batch.estimates.size()) << format;
    double worst_m = 0.0, worst_cov = 0.0;
    for (std::size_t i = 0; i < streamed.size(); ++i) {
      ASSERT_EQ(streamed[i].t_s, batch.estimates[i].t_s) << i;
      worst_m = std::max(worst_m, (streamed[i].x.w_p_b - batch.estimates[i].x.w_p_b).norm());
      worst_m = std::max(worst_m, (streamed[i].x.w_q_b.coeffs() - batch.estimates[i].x.w_q_b.coeffs()).norm());
      if (f == EstimateFormat::kTum) continue;  // TUM carries the pose only
      worst_cov = std::max(worst_cov, (streamed[i].cov_pose - batch.estimates[i].cov_pose).cwiseAbs().maxCoeff());
      EXPECT_EQ(streamed[i].phase, batch.estimates[i].phase) << i;
    }
    EXPECT_LE(worst_m, 1e-9) << format;
    EXPECT_LE(worst_cov, 1e-12) << format;
    EXPECT_NE(r.err.find("estimates"), std::string::npos) << r.err;
  }
}

TEST_F(StreamCli, AMalformedLineIsAnErrorNamingItsLineAndFieldUnderStrict) {
  const std::string events = path("bad.txt");
  {
    std::ofstream out(events);
    out << "# uwbtdoa-events v1\nimu,0,0,0,9.81,0,0,0\ntdoa,0.001,0,1,zz\n";
  }
  const test::CliResult r = test::runCli("stream --anchors " + survey_ + " --strict < " + events);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("<stdin>:3:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("tdoa_m"), std::string::npos) << r.err;
}

TEST_F(StreamCli, ReplayAtSpeedOneTakesTheFlightsDuration) {
  // GIVEN 1 s of the flight
  const std::string one_s = path("one_s.csv");
  writeFlightCsv(sliceFlight(readFlightCsv(short_), 12.0, 13.0), one_s);
  // WHEN it is replayed in real time, and as fast as possible
  const auto t0 = std::chrono::steady_clock::now();
  const test::CliResult paced = test::runCli("replay " + one_s + " --speed 1");
  const double paced_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const test::CliResult fast = test::runCli("replay " + one_s);
  // THEN the paced run lasts about the second the events span, and both print the same lines
  ASSERT_EQ(paced.exit_code, 0) << paced.err;
  EXPECT_GT(paced_s, 0.95);
  EXPECT_LT(paced_s, 10.0);
  EXPECT_EQ(paced.out, fast.out);
  EXPECT_GT(paced.out.size(), 10000u);
}

/// Reads what is available on `fd` into `out` for up to `timeout_ms`; false at end of file.
bool readFor(int fd, std::string& out, int timeout_ms) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, timeout_ms) <= 0) return true;
  char buf[65536];
  const ssize_t n = ::read(fd, buf, sizeof buf);
  if (n <= 0) return false;
  out.append(buf, static_cast<std::size_t>(n));
  return true;
}

TEST_F(StreamCli, SigintEndsTheStreamCleanlyWithItsOutputFlushed) {
  // GIVEN `stream` fed through a pipe that stays open (a live sensor), after 5 s of a flight's events
  const test::CliResult replay = test::runCli("replay " + short_);
  ASSERT_EQ(replay.exit_code, 0);
  int in[2], out[2];
  ASSERT_EQ(::pipe(in), 0);
  ASSERT_EQ(::pipe(out), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::dup2(in[0], STDIN_FILENO);
    ::dup2(out[1], STDOUT_FILENO);
    ::close(in[1]);
    ::close(out[0]);
    const std::string cli = test::cliPath();
    ::execl(cli.c_str(), cli.c_str(), "stream", "--anchors", survey_.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  // the sensor side writes from its own thread: stream's stdout pipe fills while we feed it
  std::thread feeder([&] {
    std::size_t done = 0;
    while (done < replay.out.size()) {
      const ssize_t n = ::write(in[1], replay.out.data() + done, replay.out.size() - done);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
  });
  std::string got;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (got.find("\"t\":16.9") == std::string::npos && std::chrono::steady_clock::now() < deadline)
    ASSERT_TRUE(readFor(out[0], got, 100));
  feeder.join();
  // WHEN SIGINT arrives while it waits for more input
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  while (readFor(out[0], got, 100) && std::chrono::steady_clock::now() < deadline) {
  }
  int status = 0;
  for (int k = 0; k < 200 && ::waitpid(pid, &status, WNOHANG) == 0; ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const bool exited = ::waitpid(pid, &status, WNOHANG) != 0 || WIFEXITED(status) || WIFSIGNALED(status);
  if (!exited) ::kill(pid, SIGKILL);
  ::close(in[1]);
  ::close(out[0]);
  // THEN it exits 0, and every line it wrote is a whole estimate, the last one the final one at the last stamp
  ASSERT_TRUE(exited);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), '\n');
  const std::vector<LocalizerEstimate> e = parseLines(got, EstimateFormat::kJson, false);
  ASSERT_GT(e.size(), 400u);
  EXPECT_GT(e.back().t_s, 16.99);
}

}  // namespace
}  // namespace uwb
