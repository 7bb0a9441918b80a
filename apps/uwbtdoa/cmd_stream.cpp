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

uwb::EstimateFormat estimateFormat(const StreamArgs& a) {
  if (a.output_period != 0.0) uwb::app::checkPeriod(a.output_period, "--output-period", kMaxOutputPeriod_s);
  if (a.format != "json" && a.format != "csv" && a.format != "tum")
    throw uwb::InputError("--format: expected json, csv or tum, got '" + a.format + "'");
  return a.format == "csv"   ? uwb::EstimateFormat::kCsv
         : a.format == "tum" ? uwb::EstimateFormat::kTum
                             : uwb::EstimateFormat::kJson;
}

/// One live run: events in (stdin or a ZeroMQ SUB), the estimator, estimates out (stdout or a ZeroMQ PUB), and what
/// it counts and reports on the way.
class StreamRun {
 public:
  using Clock = std::chrono::steady_clock;

  StreamRun(const StreamArgs& a, uwb::EstimateFormat format, const uwb::AnchorTable& anchors,
            uwb::EstimateStream& stream, uwb::app::Warnings& warnings)
      : a_(a), format_(format), anchors_(anchors), stream_(stream), warnings_(warnings) {
    if (!a.in.empty()) {
      sub_ = std::make_unique<uwb::ZmqLineSubscriber>(ctx_, a.in, uwb::kEventTopic);
      sub_->setIdleTimeout(a.idle_timeout);
    }
    if (!a.out.empty()) pub_ = std::make_unique<uwb::ZmqLinePublisher>(ctx_, a.out, uwb::kEstimateTopic, false);
    if (format != uwb::EstimateFormat::kJson) emit(uwb::estimateHeader(format));
  }

  /// Every event until the end of the input, a stop signal or the idle timeout; then the last estimate.
  void run() {
    for (std::string line; next(line);) handle(line);
    if (stream_.finish()) {
      emit(uwb::formatEstimate(stream_.last(), format_));
      ++n_out_;
    }
  }

  /// The warnings of the end, the end marker, the flush; then the totals (and with --stats the latency) on stderr.
  void finish() {
    for (const std::string& w : uwb::sensorRangeWarnings(stream_.sensorRange())) warnings_.add(w);  // (F31)
    if (sub_ && sub_->timedOut())
      warnings_.add(fmt::format("no message for {} (--idle-timeout): the producer is gone? ending the stream",
                                seconds(a_.idle_timeout)));
    if (pub_) pub_->send(uwb::kEndOfEvents);  // tells the consumer the stream ended (may be dropped like any estimate)
    sink_.flush();
    if (!reader_.error().empty()) throw uwb::FileError("stream: reading stdin: " + reader_.error());
    printTotals();
    if (a_.stats) printStats();
  }

 private:
  void emit(const std::string& line) {
    if (pub_) pub_->send(line);  // never blocks: a slow consumer loses estimates (counted), never sensor events
    else sink_.write(line);
  }

  bool next(std::string& line) {
    if (sub_) return sub_->next(line, uwb::app::stopFlag());
    return sink_.ok() && reader_.next(line);
  }

  std::size_t lineNumber() const { return sub_ ? sub_->messageNumber() : reader_.lineNumber(); }
  const char* unit() const { return sub_ ? "message" : "line"; }

  void handle(const std::string& line) {
    const Clock::time_point t_arrival = a_.stats ? Clock::now() : Clock::time_point{};
    const std::size_t line_no = lineNumber();
    const std::string source = sub_ ? "<zmq>" : "<stdin>";
    uwb::StreamEvent ev;
    try {
      ev = uwb::parseEventLine(line, line_no, source);
      uwb::checkEventAnchors(ev, anchors_, line_no, source);
    } catch (const uwb::InputError& e) {
      if (a_.strict) throw;
      // a live tool keeps going: the line is skipped, counted and (the first few) reported
      if (++n_bad_ <= kMaxReported)
        warnings_.add(std::string(e.what()) + "; line skipped" +
                      (n_bad_ == kMaxReported ? " (further bad lines are only counted)" : ""));
      return;
    }
    const bool out = stream_.add(ev);
    reportClockTrouble(line_no);
    if (out) {
      emit(uwb::formatEstimate(stream_.last(), format_));
      ++n_out_;
    }
    if (a_.stats) {
      const Clock::time_point t_done = Clock::now();
      const double dt_s = std::chrono::duration<double>(t_done - t_arrival).count();
      latency_all_.add(dt_s);
      if (out) latency_out_.add(dt_s);
      busy_s_ += dt_s;
      if (t_first_ == Clock::time_point{}) t_first_ = t_arrival;
      t_last_ = t_done;
    }
  }

  /// A new clock jump, and new events skipped off the sensor clock (the first kMaxReported), as warnings.
  void reportClockTrouble(std::size_t line_no) {
    if (stream_.clockJumps().size() > n_jumps_reported_) {
      const uwb::StreamClockJump& j = stream_.clockJumps()[n_jumps_reported_++];
      warnings_.add(fmt::format("THE SENSOR CLOCK JUMPED from {} to {} (near {} {}; a reboot or a stepped clock): the "
                                "estimator starts again from scratch on the new clock",
                                seconds(j.t_from_s), seconds(j.t_to_s), unit(), line_no));
    }
    if (stream_.stampOutliers() > n_outliers_reported_) {
      if (n_outliers_reported_ < kMaxReported)
        warnings_.add(fmt::format("{} event(s) before {} {} skipped: stamp {} is off the sensor clock (latest {})",
                                  stream_.stampOutliers() - n_outliers_reported_, unit(), line_no,
                                  seconds(stream_.lastOutlierStamp()), seconds(stream_.lastOutlierClock())));
      n_outliers_reported_ = stream_.stampOutliers();
    }
  }

  void printTotals() const {
    std::cerr << "stream: " << stream_.eventsIn() << " events, " << n_out_ << " estimates";
    if (n_bad_ > 0) std::cerr << ", " << n_bad_ << " bad lines skipped";
    if (stream_.stampOutliers() > 0) std::cerr << ", " << stream_.stampOutliers() << " events off the clock skipped";
    if (const std::size_t n_range = stream_.sensorRange().total(); n_range > 0)
      std::cerr << ", " << n_range << " sensor values out of range skipped";
    if (!stream_.clockJumps().empty()) std::cerr << ", " << stream_.clockJumps().size() << " clock jumps (restarts)";
    if (sub_ && sub_->timedOut()) std::cerr << " (idle timeout)";
    if (pub_) std::cerr << ", " << pub_->sent() << " sent, " << pub_->dropped() << " dropped (slow consumer)";
    std::cerr << (*uwb::app::stopFlag() ? " (stopped by signal)" : "") << (sink_.ok() ? "" : " (stdout closed)")
              << "\n";
  }

  /// --stats: latency per event (arrival to handled / to the estimate sent) and throughput.
  void printStats() const {
    const double wall_s = std::chrono::duration<double>(t_last_ - t_first_).count();
    std::cerr << "stream: latency per event, arrival to handled: " << latency_all_.summary() << "\n"
              << "stream: latency per event with an estimate, arrival to sent: " << latency_out_.summary() << "\n"
              << "stream: throughput " << (busy_s_ > 0 ? static_cast<double>(latency_all_.size()) / busy_s_ : 0.0)
              << " events/s of handling time; "
              << (wall_s > 0 ? static_cast<double>(latency_all_.size()) / wall_s : 0.0) << " events/s received over "
              << wall_s << " s\n";
  }

  const StreamArgs& a_;
  const uwb::EstimateFormat format_;
  const uwb::AnchorTable& anchors_;
  uwb::EstimateStream& stream_;
  uwb::app::Warnings& warnings_;
  zmq::context_t ctx_;
  std::unique_ptr<uwb::ZmqLineSubscriber> sub_;
  std::unique_ptr<uwb::ZmqLinePublisher> pub_;
  LineSink sink_;
  uwb::FdLineReader reader_{STDIN_FILENO, uwb::app::stopFlag(), [this] { sink_.flush(); }};
  std::size_t n_out_ = 0, n_bad_ = 0, n_outliers_reported_ = 0, n_jumps_reported_ = 0;
  uwb::LatencyStats latency_all_, latency_out_;
  Clock::time_point t_first_{}, t_last_{};
  double busy_s_ = 0.0;
};

void runStream(const StreamArgs& a) {
  const uwb::EstimateFormat format = estimateFormat(a);
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
  StreamRun live(a, format, anchors, stream, warnings);
  live.run();
  live.finish();
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
