/** @file ZmqWire.h
 *  @brief The ZeroMQ wire format of `stream` and `replay` (docs/io.md §5), version 1: a two-frame multipart message,
 *         frame 1 the topic (which names the version), frame 2 one line of the text protocol without newline:
 *
 *    "uwb.events.v1"     | "imu,0.001,…"        sensor events (LineProtocol.h); "# end" closes the stream
 *    "uwb.estimates.v1"  | "{\"t\":…}" or a CSV row (EstimateFormat.h)
 *
 *  The sender of sensor events never drops one: its PUB socket blocks at the high-water mark (ZMQ_XPUB_NODROP)
 *  and waits for the first subscriber before it sends. The estimate publisher never blocks: a message that does not
 *  fit is dropped and counted.
 */
#pragma once

#include <chrono>
#include <cstddef>
#include <csignal>
#include <string>
#include <string_view>
#include <zmq.hpp>

namespace uwb {

inline constexpr std::string_view kEventTopic = "uwb.events.v1";
inline constexpr std::string_view kEstimateTopic = "uwb.estimates.v1";
inline constexpr std::string_view kEndOfEvents = "# end";

/// Receives lines of one topic on a SUB socket connected to `endpoint`.
class ZmqLineSubscriber {
 public:
  ZmqLineSubscriber(zmq::context_t& ctx, const std::string& endpoint, std::string_view topic);
  /// The next message's line; false at "# end", when *stop is set (checked every 100 ms) or when no message came for
  /// the idle timeout (then timedOut()). Throws InputError naming the message number on a message that is not two
  /// frames or whose topic is another version.
  bool next(std::string& line, const volatile std::sig_atomic_t* stop);
  std::size_t messageNumber() const { return n_; }
  /// Seconds without a message after which next() gives up (a producer that was killed never sends "# end");
  /// ≤ 0: wait forever. The clock starts at construction and restarts at every message.
  void setIdleTimeout(double seconds) { idle_timeout_s_ = seconds; }
  bool timedOut() const { return timed_out_; }

 private:
  zmq::socket_t sock_;
  std::string topic_;
  std::size_t n_ = 0;
  double idle_timeout_s_ = 0.0;
  bool timed_out_ = false;
  std::chrono::steady_clock::time_point t_last_message_;
};

/// Sends lines of one topic on a PUB socket bound to `endpoint`.
class ZmqLinePublisher {
 public:
  /// reliable: block at the high-water mark (sensor events); otherwise drop and count (estimates).
  ZmqLinePublisher(zmq::context_t& ctx, const std::string& endpoint, std::string_view topic, bool reliable);
  /// Waits up to timeout_ms for a first subscriber (XPUB subscription message); false on timeout or stop.
  bool waitForSubscriber(int timeout_ms, const volatile std::sig_atomic_t* stop);
  /// Sends one line; false when it was dropped (non-reliable only).
  bool send(std::string_view line);
  std::size_t sent() const { return n_sent_; }
  std::size_t dropped() const { return n_dropped_; }

 private:
  zmq::socket_t sock_;
  std::string topic_;
  bool reliable_;
  std::size_t n_sent_ = 0, n_dropped_ = 0;
};

}  // namespace uwb
