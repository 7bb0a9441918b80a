/** @file ZmqWireTest.cpp
 *  @brief The version-1 wire format in one process (inproc transport): lines arrive in order and "# end" closes the
 *         stream; a message of another version or with one frame is an input error naming the message number.
 */
#include <gtest/gtest.h>

#include <string>
#include <zmq.hpp>

#include "uwb/core/Error.h"
#include "uwb/stream/ZmqWire.h"

namespace uwb {
namespace {

TEST(ZmqWire, LinesArriveInOrderUntilTheEndMarker) {
  zmq::context_t ctx;
  ZmqLinePublisher pub(ctx, "inproc://wire-order", kEventTopic, /*reliable=*/true);
  ZmqLineSubscriber sub(ctx, "inproc://wire-order", kEventTopic);
  ASSERT_TRUE(pub.waitForSubscriber(5000, nullptr));
  for (int k = 0; k < 100; ++k) pub.send("tof," + std::to_string(k) + ",1.5");
  pub.send(kEndOfEvents);
  std::string line;
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(sub.next(line, nullptr));
    EXPECT_EQ(line, "tof," + std::to_string(k) + ",1.5");
  }
  EXPECT_FALSE(sub.next(line, nullptr));  // "# end"
  EXPECT_EQ(sub.messageNumber(), 101u);
  EXPECT_EQ(pub.sent(), 101u);
  EXPECT_EQ(pub.dropped(), 0u);
}

TEST(ZmqWire, AnotherVersionIsAnErrorNamingTheMessage) {
  zmq::context_t ctx;
  ZmqLinePublisher pub(ctx, "inproc://wire-version", "uwb.events.v2", true);
  ZmqLineSubscriber sub(ctx, "inproc://wire-version", kEventTopic);
  ASSERT_TRUE(pub.waitForSubscriber(5000, nullptr));
  pub.send("imu,0,0,0,9.81,0,0,0");
  std::string line;
  try {
    sub.next(line, nullptr);
    FAIL() << "no error for a v2 message";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().line, 1u);
    EXPECT_EQ(e.where().field, "topic");
    EXPECT_NE(std::string(e.what()).find("uwb.events.v2"), std::string::npos) << e.what();
  }
}

TEST(ZmqWire, AOneFrameMessageIsAnError) {
  zmq::context_t ctx;
  zmq::socket_t raw(ctx, zmq::socket_type::xpub);
  raw.bind("inproc://wire-frames");
  ZmqLineSubscriber sub(ctx, "inproc://wire-frames", kEventTopic);
  zmq::message_t subscription;
  ASSERT_TRUE(raw.recv(subscription));  // the subscriber is there
  raw.send(zmq::buffer(std::string("uwb.events.v1")), zmq::send_flags::none);
  std::string line;
  EXPECT_THROW(sub.next(line, nullptr), InputError);
}

TEST(ZmqWire, ASubscriberStopsOnTheFlag) {
  zmq::context_t ctx;
  ZmqLineSubscriber sub(ctx, "inproc://wire-silent", kEventTopic);
  volatile std::sig_atomic_t stop = 1;
  std::string line;
  EXPECT_FALSE(sub.next(line, &stop));
}

}  // namespace
}  // namespace uwb
