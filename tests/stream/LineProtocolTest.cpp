/** @file LineProtocolTest.cpp
 *  @brief The sensor-event line protocol: exact round trip of every event type, comments, and malformed lines
 *         reported with their line number, column and field.
 */
#include <gtest/gtest.h>

#include <string>

#include "uwb/core/Error.h"
#include "uwb/stream/LineProtocol.h"

namespace uwb {
namespace {

TEST(LineProtocol, EveryEventTypeReadsBackBitForBit) {
  // GIVEN events with values that have no short decimal form
  ImuReading imu;
  imu.b_acc_mps2 = Vec3(0.1 + 0.2, -9.81 / 3.0, 1e-300);
  imu.b_gyro_radps = Vec3(1.0 / 7.0, -2.0 / 3.0, 123456.789e10);
  const TdoaMeasurement z{12.000000000000002, 3, 7, -1.0 / 3.0};
  const TofObservation tof{12.5, 0.1 + 0.7};
  // WHEN written and read back
  const StreamEvent e_imu = parseEventLine(formatImuLine(0.1 * 3.0, imu), 1);
  const StreamEvent e_tdoa = parseEventLine(formatTdoaLine(z), 2);
  const StreamEvent e_tof = parseEventLine(formatTofLine(tof), 3);
  // THEN every value is the same double
  ASSERT_EQ(e_imu.kind, StreamEvent::Kind::kImu);
  EXPECT_EQ(e_imu.t_s, 0.1 * 3.0);
  EXPECT_EQ(e_imu.imu.b_acc_mps2, imu.b_acc_mps2);
  EXPECT_EQ(e_imu.imu.b_gyro_radps, imu.b_gyro_radps);
  ASSERT_EQ(e_tdoa.kind, StreamEvent::Kind::kTdoa);
  EXPECT_EQ(e_tdoa.t_s, z.t_s);
  EXPECT_EQ(e_tdoa.tdoa.t_s, z.t_s);
  EXPECT_EQ(e_tdoa.tdoa.id_a, 3);
  EXPECT_EQ(e_tdoa.tdoa.id_b, 7);
  EXPECT_EQ(e_tdoa.tdoa.tdoa_m, z.tdoa_m);
  ASSERT_EQ(e_tof.kind, StreamEvent::Kind::kTof);
  EXPECT_EQ(e_tof.tof.range_m, tof.range_m);
}

TEST(LineProtocol, CommentsBlankLinesSpacesAndCarriageReturnsAreAccepted) {
  EXPECT_EQ(parseEventLine("# uwbtdoa-events v1", 1).kind, StreamEvent::Kind::kNone);
  EXPECT_EQ(parseEventLine("   ", 2).kind, StreamEvent::Kind::kNone);
  EXPECT_EQ(parseEventLine("", 3).kind, StreamEvent::Kind::kNone);
  const StreamEvent e = parseEventLine("tdoa, 1.5 ,0, 1 ,0.25\r", 4);
  ASSERT_EQ(e.kind, StreamEvent::Kind::kTdoa);
  EXPECT_EQ(e.tdoa.tdoa_m, 0.25);
  EXPECT_EQ(e.t_s, 1.5);
}

/// The InputError of parsing `line` as line 17 (fails the test when there is none).
InputError errorOf(const std::string& line) {
  try {
    parseEventLine(line, 17);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for: " << line;
  return InputError("none");
}

TEST(LineProtocol, AMalformedLineNamesItsLineColumnAndField) {
  struct Case {
    const char* line;
    const char* field;
    std::size_t column;
  };
  const Case cases[] = {
      {"imu,0.1,0,0,9.81,0,x,0", "gy", 20},           // not a number
      {"imu,0.1,0,0,9.81,0,0", "missing field", 20},  // 7 fields
      {"tdoa,1,0,1,0.2,5", "extra field", 16},        // 6 fields
      {"tdoa,1,0.5,1,0.2", "id_a", 8},                // id not an integer
      {"tdoa,nan,0,1,0.2", "t", 6},                   // not finite
      {"tof,1,inf", "range_m", 7},
      {"tof,1,", "range_m", 7},                       // empty
      {"baro,1,100", "type", 1},                      // unknown type
      {"imu,1e999,0,0,0,0,0,0", "t", 5},              // out of range
  };
  for (const Case& c : cases) {
    const InputError e = errorOf(c.line);
    EXPECT_EQ(e.where().line, 17u) << c.line;
    EXPECT_EQ(e.where().field, c.field) << c.line << ": " << e.what();
    EXPECT_EQ(e.where().column, c.column) << c.line << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find(":17:"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwb
