/** @file ZmqWire.cpp
 *  @brief Version-1 multipart messages over ZeroMQ PUB/SUB.
 */
#include "uwb/stream/ZmqWire.h"

#include <chrono>

#include "uwb/core/Error.h"

namespace uwb {
namespace {
constexpr int kPoll_ms = 100;

/// Waits up to kPoll_ms for a message on the socket; false on a timeout or a signal (EINTR), so that the caller
/// checks its stop flag and deadline again.
bool readableWithinPoll(zmq::socket_t& sock) {
  zmq::pollitem_t item{sock.handle(), 0, ZMQ_POLLIN, 0};
  try {
    return zmq::poll(&item, 1, std::chrono::milliseconds(kPoll_ms)) != 0;
  } catch (const zmq::error_t& e) {
    if (e.num() == EINTR) return false;
    throw;
  }
}
}  // namespace

ZmqLineSubscriber::ZmqLineSubscriber(zmq::context_t& ctx, const std::string& endpoint, std::string_view topic)
    : sock_(ctx, zmq::socket_type::sub), topic_(topic) {
  sock_.set(zmq::sockopt::rcvhwm, 0);  // never drop sensor events on the receiving side
  sock_.set(zmq::sockopt::linger, 0);
  // subscribe to the topic family ("uwb.events."), so another version is reported instead of ignored
  sock_.set(zmq::sockopt::subscribe, topic_.substr(0, topic_.rfind('.') + 1));
  sock_.connect(endpoint);
  t_last_message_ = std::chrono::steady_clock::now();
}

bool ZmqLineSubscriber::next(std::string& line, const volatile std::sig_atomic_t* stop) {
  while (stop == nullptr || *stop == 0) {
    if (idle_timeout_s_ > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_last_message_).count() >= idle_timeout_s_) {
      timed_out_ = true;
      return false;
    }
    if (!readableWithinPoll(sock_)) continue;
    zmq::message_t topic, body;
    if (!sock_.recv(topic, zmq::recv_flags::dontwait)) continue;
    t_last_message_ = std::chrono::steady_clock::now();
    ++n_;
    const SourceLocation where{"<zmq>", n_, 0, "topic"};
    if (!topic.more()) throw InputError(where, "a message must have two frames (topic, line), this one has one");
    if (!sock_.recv(body)) throw InputError(where, "the message's second frame is missing");
    if (body.more()) throw InputError(SourceLocation{"<zmq>", n_, 0, "line"}, "more than two frames");
    if (topic.to_string_view() != topic_)
      throw InputError(where, "topic '" + topic.to_string() + "', expected '" + topic_ + "' (another wire version?)");
    line = body.to_string();
    if (line == kEndOfEvents) return false;
    return true;
  }
  return false;
}

ZmqLinePublisher::ZmqLinePublisher(zmq::context_t& ctx, const std::string& endpoint, std::string_view topic,
                                   bool reliable)
    : sock_(ctx, zmq::socket_type::xpub), topic_(topic), reliable_(reliable) {
  sock_.set(zmq::sockopt::xpub_nodrop, 1);  // at the high-water mark: block (reliable) or EAGAIN (counted drop)
  sock_.set(zmq::sockopt::linger, 2000);  // at close: up to 2 s to deliver what is queued (the last estimates, "# end")
  sock_.bind(endpoint);
}

bool ZmqLinePublisher::waitForSubscriber(int timeout_ms, const volatile std::sig_atomic_t* stop) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (std::chrono::steady_clock::now() < deadline && (stop == nullptr || *stop == 0)) {
    if (!readableWithinPoll(sock_)) continue;
    zmq::message_t sub;
    if (sock_.recv(sub, zmq::recv_flags::dontwait) && sub.size() > 0 && sub.data<char>()[0] == 1) return true;
  }
  return false;
}

bool ZmqLinePublisher::send(std::string_view line) {
  const zmq::send_flags flags = reliable_ ? zmq::send_flags::none : zmq::send_flags::dontwait;
  // a multipart message is atomic: if the first frame goes, the second does too
  if (!sock_.send(zmq::buffer(topic_), flags | zmq::send_flags::sndmore)) {
    ++n_dropped_;
    return false;
  }
  sock_.send(zmq::buffer(line), zmq::send_flags::none);
  ++n_sent_;
  return true;
}

}  // namespace uwb
