/** @file cmd_stream.cpp
 *  @brief `uwbtdoa stream --anchors SURVEY [--in ENDPOINT] [--out ENDPOINT] [--format json|csv] [--output-period S]
 *         [--config FILE] ...`: reads sensor events (the line protocol of docs/io.md §5) from stdin or a ZeroMQ
 *         socket and writes estimates to stdout or a ZeroMQ PUB socket as they are made.
 *         Ends cleanly (flush, exit 0) at the end of input, on SIGINT/SIGTERM and when a ZeroMQ producer falls silent
 *         for --idle-timeout seconds. A malformed line, or a TDoA naming an anchor outside the survey, is skipped,
 *         counted and reported (the first few with line number and reason); with --strict it is an input error.
 *         Stamps off the sensor clock go through EstimateStream's clock guard (docs/io.md §5).
 */
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <unistd.h>

#include "Command.h"
#include "FilterOptions.h"
#include "InputGuards.h"
#include "StopSignal.h"
#include "uwb/core/Error.h"
#include "uwb/eval/Localization.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/stream/EstimateFormat.h"
#include "uwb/stream/EstimateStream.h"
#include "uwb/stream/FdLineReader.h"
#include "uwb/stream/LatencyStats.h"
#include "uwb/stream/ZmqWire.h"

namespace {

struct StreamArgs {
  std::string anchors, format = "json", in, out;
  double output_period = 0.01;
  double idle_timeout = 10.0;
  bool stats = false;
  bool strict = false;
  uwb::app::FilterOptionArgs filter;
};

constexpr double kMaxOutputPeriod_s = 60.0;
/// Bad lines and skipped stamps reported one by one; the rest only in the totals at the end.
constexpr std::size_t kMaxReported = 10;

std::string seconds(double t_s) { return fmt::format("{:.6g} s", t_s); }

/// Estimate lines to stdout, flushed whenever the input side is about to wait.
class LineSink {
 public:
  void write(const std::string& line) {
    buf_ += line;
    buf_ += '\n';
    if (buf_.size() > (1u << 16)) flush();
  }
  void flush() {
    std::size_t done = 0;
    while (done < buf_.size() && ok_) {
      const ssize_t n = ::write(STDOUT_FILENO, buf_.data() + done, buf_.size() - done);
      if (n > 0) done += static_cast<std::size_t>(n);
      else if (n < 0 && errno != EINTR) ok_ = false;  // consumer gone (SIGPIPE ignored): stop writing
    }
    buf_.clear();
  }
  bool ok() const { return ok_; }

 private:
  std::string buf_;
  bool ok_ = true;
};

void runStream(const StreamArgs& a) {
  if (a.output_period != 0.0) uwb::app::checkPeriod(a.output_period, "--output-period", kMaxOutputPeriod_s);
  if (a.format != "json" && a.format != "csv" && a.format != "tum")
    throw uwb::InputError("--format: expected json, csv or tum, got '" + a.format + "'");
  const uwb::EstimateFormat format = a.format == "csv"   ? uwb::EstimateFormat::kCsv
                                     : a.format == "tum" ? uwb::EstimateFormat::kTum
                                                         : uwb::EstimateFormat::kJson;
  uwb::app::FilterSetup setup = uwb::app::buildFilterParams(a.filter);
  const uwb::BiasPredictor bias = uwb::app::loadBiasPredictor(a.filter, &setup.params);
  const uwb::AnchorSurvey survey = uwb::readAnchorSurvey(a.anchors);
  if (!(a.idle_timeout >= 0.0) || !std::isfinite(a.idle_timeout))
    throw std::invalid_argument("--idle-timeout: expected a finite number of seconds ≥ 0 (0: wait forever)");
  uwb::app::Warnings warnings;
  warnings.addIssues(uwb::checkSurveyGeometry(survey));
  const uwb::AnchorTable anchors = uwb::anchorTableFromSurvey(survey, setup.params.anchor_sigma_m);
  uwb::EstimateStream stream(setup.params, anchors, a.output_period, bias);

  uwb::app::installStopHandlers();
  zmq::context_t ctx;
  std::unique_ptr<uwb::ZmqLineSubscriber> sub;
  std::unique_ptr<uwb::ZmqLinePublisher> pub;
  if (!a.in.empty()) {
    sub = std::make_unique<uwb::ZmqLineSubscriber>(ctx, a.in, uwb::kEventTopic);
    sub->setIdleTimeout(a.idle_timeout);
  }
  if (!a.out.empty()) pub = std::make_unique<uwb::ZmqLinePublisher>(ctx, a.out, uwb::kEstimateTopic, false);
  LineSink sink;
  const auto emit = [&](const std::string& line) {
    if (pub) pub->send(line);  // never blocks: a slow consumer loses estimates (counted), never sensor events
    else sink.write(line);
  };
  if (format != uwb::EstimateFormat::kJson) emit(uwb::estimateHeader(format));
  uwb::FdLineReader reader(STDIN_FILENO, uwb::app::stopFlag(), [&sink] { sink.flush(); });
  const auto next = [&](std::string& line) {
    if (sub) {
      if (!sub->next(line, uwb::app::stopFlag())) return false;
      return true;
    }
    return sink.ok() && reader.next(line);
  };
  const std::string source = sub ? "<zmq>" : "<stdin>";
  std::size_t n_out = 0;
  uwb::LatencyStats latency_all, latency_out;  // --stats: arrival → handled (all events) / → estimate sent
  using Clock = std::chrono::steady_clock;
  Clock::time_point t_first{}, t_last{};
  double busy_s = 0.0;
  std::size_t n_bad = 0, n_outliers_reported = 0, n_jumps_reported = 0;
  for (std::string line; next(line);) {
    const Clock::time_point t_arrival = a.stats ? Clock::now() : Clock::time_point{};
    const std::size_t line_no = sub ? sub->messageNumber() : reader.lineNumber();
    uwb::StreamEvent ev;
    try {
      ev = uwb::parseEventLine(line, line_no, source);
      uwb::checkEventAnchors(ev, anchors, line_no, source);
    } catch (const uwb::InputError& e) {
      if (a.strict) throw;
      // a live tool keeps going: the line is skipped, counted and (the first few) reported
      if (++n_bad <= kMaxReported)
        warnings.add(std::string(e.what()) + "; line skipped" +
                     (n_bad == kMaxReported ? " (further bad lines are only counted)" : ""));
      continue;
    }
    const bool out = stream.add(ev);
    if (stream.clockJumps().size() > n_jumps_reported) {
      const uwb::StreamClockJump& j = stream.clockJumps()[n_jumps_reported++];
      warnings.add(fmt::format("THE SENSOR CLOCK JUMPED from {} to {} (near {} {}; a reboot or a stepped clock): the "
                               "estimator starts again from scratch on the new clock",
                               seconds(j.t_from_s), seconds(j.t_to_s), sub ? "message" : "line", line_no));
    }
    if (stream.stampOutliers() > n_outliers_reported) {
      if (n_outliers_reported < kMaxReported)
        warnings.add(fmt::format("{} event(s) before {} {} skipped: stamp {} is off the sensor clock (latest {})",
                                 stream.stampOutliers() - n_outliers_reported, sub ? "message" : "line", line_no,
                                 seconds(stream.lastOutlierStamp()), seconds(stream.lastOutlierClock())));
      n_outliers_reported = stream.stampOutliers();
    }
    if (out) {
      emit(uwb::formatEstimate(stream.last(), format));
      ++n_out;
    }
    if (a.stats) {
      const Clock::time_point t_done = Clock::now();
      const double dt_s = std::chrono::duration<double>(t_done - t_arrival).count();
      latency_all.add(dt_s);
      if (out) latency_out.add(dt_s);
      busy_s += dt_s;
      if (t_first == Clock::time_point{}) t_first = t_arrival;
      t_last = t_done;
    }
  }
  if (stream.finish()) {
    emit(uwb::formatEstimate(stream.last(), format));
    ++n_out;
  }
  for (const std::string& w : uwb::sensorRangeWarnings(stream.sensorRange())) warnings.add(w);  // (F31)
  if (sub && sub->timedOut())
    warnings.add(fmt::format("no message for {} (--idle-timeout): the producer is gone? ending the stream",
                             seconds(a.idle_timeout)));
  if (pub) pub->send(uwb::kEndOfEvents);  // tells the consumer the stream ended (may be dropped like any estimate)
  sink.flush();
  if (!reader.error().empty()) throw uwb::FileError("stream: reading stdin: " + reader.error());
  std::cerr << "stream: " << stream.eventsIn() << " events, " << n_out << " estimates";
  if (n_bad > 0) std::cerr << ", " << n_bad << " bad lines skipped";
  if (stream.stampOutliers() > 0) std::cerr << ", " << stream.stampOutliers() << " events off the clock skipped";
  if (const std::size_t n_range = stream.sensorRange().total(); n_range > 0)
    std::cerr << ", " << n_range << " sensor values out of range skipped";
  if (!stream.clockJumps().empty()) std::cerr << ", " << stream.clockJumps().size() << " clock jumps (restarts)";
  if (sub && sub->timedOut()) std::cerr << " (idle timeout)";
  if (pub) std::cerr << ", " << pub->sent() << " sent, " << pub->dropped() << " dropped (slow consumer)";
  std::cerr << (*uwb::app::stopFlag() ? " (stopped by signal)" : "") << (sink.ok() ? "" : " (stdout closed)") << "\n";
  if (a.stats) {
    const double wall_s = std::chrono::duration<double>(t_last - t_first).count();
    std::cerr << "stream: latency per event, arrival to handled: " << latency_all.summary() << "\n"
              << "stream: latency per event with an estimate, arrival to sent: " << latency_out.summary() << "\n"
              << "stream: throughput " << (busy_s > 0 ? static_cast<double>(latency_all.size()) / busy_s : 0.0)
              << " events/s of handling time; " << (wall_s > 0 ? static_cast<double>(latency_all.size()) / wall_s : 0.0)
              << " events/s received over " << wall_s << " s\n";
  }
}

const bool kRegistered = uwb::app::registerCommand(
    {"stream", "Localize live: sensor events on stdin (docs/io.md line protocol), estimates on stdout",
     [](CLI::App& sub) {
       auto a = std::make_shared<StreamArgs>();
       sub.add_option("--anchors", a->anchors, "Anchor survey (UTIL survey text)")->required();
       sub.add_option("--format", a->format,
                      "Estimate lines: json (one object per line), csv, or tum (t x y z qx qy qz qw, pose only, for "
                      "evo)")
           ->check(CLI::IsMember({"json", "csv", "tum"}));
       sub.add_option("--output-period", a->output_period,
                      "Minimum spacing of estimates [s] (0: one per IMU/TDoA event)");
       sub.add_option("--in", a->in, "Read sensor events from this ZeroMQ PUB endpoint (SUB), e.g. tcp://127.0.0.1:5555");
       sub.add_option("--out", a->out, "Publish estimates on this ZeroMQ endpoint (PUB, bound), e.g. tcp://127.0.0.1:5556");
       sub.add_option("--idle-timeout", a->idle_timeout,
                      "With --in: end (with a warning and the summary) after this many seconds without a message; "
                      "0: wait forever")
           ->capture_default_str();
       sub.add_flag("--strict", a->strict,
                    "Stop at the first malformed line or unknown anchor (exit 2) instead of skipping and counting it");
       sub.add_flag("--stats", a->stats,
                    "Print per-event latency (arrival to estimate sent: p50/p99/max) and throughput on stderr");
       uwb::app::addFilterOptions(sub, a->filter);
       sub.callback([a] { runStream(*a); });
     }});

}  // namespace
