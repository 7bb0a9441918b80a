/** @file StreamZmqTest.cpp
 *  @brief `replay --to` → `stream --in … --out …` → a subscriber, on loopback: the estimates equal those of the
 *         stdin path with none dropped for a reading consumer; a consumer that does not read loses estimates
 *         (counted) but no sensor event. Bounded in time (every process under `timeout`).
 */
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <future>
#include <regex>
#include <string>
#include <thread>
#include <unistd.h>
#include <zmq.hpp>

#include "support/CliFixture.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/stream/ZmqWire.h"

namespace uwb {
namespace {

namespace fs = std::filesystem;

class StreamZmq : public test::PilotFlightCliTest {
 protected:
  StreamZmq() : PilotFlightCliTest("0425-traj1", {{12.0, 17.0}}) {}
  /// Two loopback endpoints unlikely to be in use (per process).
  static std::string endpoint(int k) { return "tcp://127.0.0.1:" + std::to_string(40000 + (::getpid() * 2 + k) % 20000); }
};

/// Runs `timeout 60 uwbtdoa <args>`; stdout and stderr to their own files (several run at once).
test::CliResult runCli(const std::string& args, const fs::path& dir, const std::string& name) {
  const fs::path out = dir / (name + ".out"), err = dir / (name + ".err");
  const std::string cmd = "timeout 60 " + test::cliPath() + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  test::CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream o(out), e(err);
  r.out.assign(std::istreambuf_iterator<char>(o), std::istreambuf_iterator<char>());
  r.err.assign(std::istreambuf_iterator<char>(e), std::istreambuf_iterator<char>());
  return r;
}

std::future<test::CliResult> runAsync(const std::string& args, const fs::path& dir, const std::string& name) {
  return std::async(std::launch::async, [=] { return runCli(args, dir, name); });
}

std::size_t countOf(const std::string& err, const std::string& what) {
  std::smatch m;
  if (!std::regex_search(err, m, std::regex("([0-9]+) " + what))) return static_cast<std::size_t>(-1);
  return std::stoul(m[1]);
}

TEST_F(StreamZmq, LoopbackGivesTheStdinEstimatesWithNoneDropped) {
  // GIVEN the stdin path's estimates of 5 s of a real flight
  const test::CliResult piped = test::runCli("replay " + short_ + " | " + test::cliPath() + " stream --anchors " +
                                             survey_);
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  // WHEN the same flight goes replay → stream → subscriber over ZeroMQ on loopback
  const std::string in = endpoint(0), out = endpoint(1);
  zmq::context_t ctx;
  auto stream = runAsync("stream --anchors " + survey_ + " --in " + in + " --out " + out, dir(), "stream");
  ZmqLineSubscriber consumer(ctx, out, kEstimateTopic);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // both subscriptions in place
  auto replay = runAsync("replay " + short_ + " --to " + in, dir(), "replay");
  std::string received, line;
  volatile std::sig_atomic_t give_up = 0;
  std::thread watchdog([&give_up] {
    for (int k = 0; k < 300 && !give_up; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    give_up = 1;
  });
  while (consumer.next(line, &give_up)) received += line + "\n";
  give_up = 1;
  watchdog.join();
  const test::CliResult r_replay = replay.get(), r_stream = stream.get();
  // THEN both exit 0, the estimate lines are identical, and none was dropped
  EXPECT_EQ(r_replay.exit_code, 0) << r_replay.err;
  EXPECT_EQ(r_stream.exit_code, 0) << r_stream.err;
  EXPECT_GT(piped.out.size(), 100000u);
  EXPECT_TRUE(received == piped.out) << "received " << received.size() << " bytes, the stdin path " << piped.out.size();
  EXPECT_EQ(countOf(r_stream.err, "dropped"), 0u) << r_stream.err;
  EXPECT_EQ(countOf(r_stream.err, "events"), countOf(piped.err, "events"));
}

TEST_F(StreamZmq, AConsumerThatDoesNotReadLosesEstimatesButNoSensorEvent) {
  // GIVEN a subscriber that connects and never reads, and a whole flight with one estimate per event
  const std::string in = endpoint(0), out = endpoint(1);
  zmq::context_t ctx;
  zmq::socket_t idle(ctx, zmq::socket_type::sub);
  idle.set(zmq::sockopt::subscribe, "");
  idle.set(zmq::sockopt::rcvhwm, 10);
  idle.set(zmq::sockopt::rcvbuf, 4096);
  idle.set(zmq::sockopt::linger, 0);
  auto stream =
      runAsync("stream --anchors " + survey_ + " --output-period 0 --in " + in + " --out " + out, dir(), "stream");
  idle.connect(out);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  // WHEN the flight is replayed at full speed
  const test::CliResult r_replay = runCli("replay " + flight_->string() + " --to " + in, dir(), "replay");
  const test::CliResult r_stream = stream.get();
  // THEN every sensor event reached the filter, and the estimates that did not fit were counted as dropped
  ASSERT_EQ(r_replay.exit_code, 0) << r_replay.err;
  ASSERT_EQ(r_stream.exit_code, 0) << r_stream.err;
  const std::size_t n_events = countOf(r_replay.err, "events");
  EXPECT_GT(n_events, 50000u);
  EXPECT_EQ(countOf(r_stream.err, "events"), n_events) << r_stream.err;
  const std::size_t n_sent = countOf(r_stream.err, "sent"), n_dropped = countOf(r_stream.err, "dropped");
  EXPECT_GT(n_dropped, 0u) << r_stream.err;
  EXPECT_EQ(n_sent + n_dropped, countOf(r_stream.err, "estimates") + 1) << r_stream.err;  // + the end marker
}

}  // namespace
}  // namespace uwb
