/** @file cmd_replay.cpp
 *  @brief `uwbtdoa replay FLIGHT.csv [--speed max|1] [--to ENDPOINT]`: prints (or publishes) a recorded flight's merged sensor events in the line
 *         protocol of `stream` (docs/io.md §5); at --speed 1 each line leaves at its stamp's time after the first.
 */
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <thread>

#include <unistd.h>

#include "Command.h"
#include "StopSignal.h"
#include "uwb/core/Error.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/stream/LineProtocol.h"
#include "uwb/eval/Localization.h"
#include "uwb/stream/ZmqWire.h"

namespace {

struct ReplayArgs {
  std::string flight, speed = "max", to;
  int wait_ms = 10000;
};

bool writeAll(const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = ::write(STDOUT_FILENO, s.data() + done, s.size() - done);
    if (n > 0) done += static_cast<std::size_t>(n);
    else if (n < 0 && errno != EINTR) return false;
  }
  return true;
}

void runReplay(const ReplayArgs& a) {
  const bool realtime = a.speed == "1";
  const uwb::Flight flight = uwb::readFlightCsv(a.flight);
  const uwb::SensorLog log = uwb::replayLogFromFlight(flight);
  uwb::app::installStopHandlers();
  uwb::SensorEventCursor events(log);
  zmq::context_t ctx;
  std::unique_ptr<uwb::ZmqLinePublisher> pub;
  if (!a.to.empty()) {
    pub = std::make_unique<uwb::ZmqLinePublisher>(ctx, a.to, uwb::kEventTopic, true);
    if (!pub->waitForSubscriber(a.wait_ms, uwb::app::stopFlag()))
      throw uwb::InputError("replay --to " + a.to + ": no subscriber within " + std::to_string(a.wait_ms) + " ms");
  }
  std::string buf = pub ? std::string() : std::string(uwb::kEventProtocolHeader) + "\n";
  const auto wall0 = std::chrono::steady_clock::now();
  const double t0 = events.empty() ? 0.0 : events.firstStamp();
  std::size_t n = 0;
  bool ok = true;
  for (uwb::SensorEvent ev; ok && !*uwb::app::stopFlag() && events.next(ev); ++n) {
    if (realtime) {
      const auto due = wall0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(ev.t_s - t0));
      if (std::chrono::steady_clock::now() < due) {
        ok = writeAll(buf);
        buf.clear();
        std::this_thread::sleep_until(due);
      }
    }
    if (pub) {
      pub->send(uwb::formatEventLine(log, ev));  // blocks at the high-water mark: no event is dropped
      continue;
    }
    buf += uwb::formatEventLine(log, ev);
    buf += '\n';
    if (buf.size() > (1u << 16)) {
      ok = ok && writeAll(buf);
      buf.clear();
    }
  }
  if (pub) pub->send(uwb::kEndOfEvents);
  else if (ok) ok = writeAll(buf);
  std::cerr << "replay: " << n << " events" << (*uwb::app::stopFlag() ? " (stopped by signal)" : "")
            << (ok ? "" : " (stdout closed)") << "\n";
}

const bool kRegistered = uwb::app::registerCommand(
    {"replay", "Print a recorded flight's sensor events in the `stream` line protocol (optionally in real time)",
     [](CLI::App& sub) {
       auto a = std::make_shared<ReplayArgs>();
       sub.add_option("flight", a->flight, "Flight CSV (UTIL layout)")->required();
       sub.add_option("--speed", a->speed, "max: as fast as possible; 1: paced in real time")
           ->check(CLI::IsMember({"max", "1"}));
       sub.add_option("--to", a->to, "Publish on this ZeroMQ endpoint (PUB, bound) instead of stdout");
       sub.add_option("--wait-ms", a->wait_ms, "With --to: how long to wait for a first subscriber [ms]");
       sub.callback([a] { runReplay(*a); });
     }});

}  // namespace
