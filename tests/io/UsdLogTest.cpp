/** @file UsdLogTest.cpp
 *  @brief The cfusdlog reader and writer (io/UsdLog.h), the import into the UTIL flight layout (io/UsdImport.h)
 *         and `uwbtdoa import`: logs written here byte by byte, each error with its located message, and a round
 *         trip of the first seconds of a real UTIL flight.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <fmt/format.h>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "io/IoTestHelpers.h"
#include "support/UsdDeckConfig.h"
#include "uwb/core/Error.h"
#include "uwb/io/FlightWindow.h"
#include "uwb/io/UsdImport.h"
#include "uwb/io/UsdLog.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

constexpr auto F = UsdType::kFloat;

double f32(double x) { return static_cast<double>(static_cast<float>(x)); }

/// A log as the UTIL firmware wrote it: every stream's event type (with the dataset's field names and types),
/// plus an event type outside the flight layout. Two samples per stream at known times.
UsdLog utilStyleLog(int version = 2) {
  UsdLog log;
  log.source = "built.log";
  const std::size_t tdoa = log.addType(7, "estTDOA", {{"idA", UsdType::kUint8}, {"idB", UsdType::kUint8}, {"distanceDiff", F}});
  const std::size_t acc = log.addType(3, "estAcceleration", {{"acc.x", F}, {"acc.y", F}, {"acc.z", F}});
  const std::size_t gyro = log.addType(4, "estGyroscope", {{"gyro.x", F}, {"gyro.y", F}, {"gyro.z", F}});
  const std::size_t tof = log.addType(5, "estTOF", {{"range.zrange", UsdType::kUint16}});
  const std::size_t flow = log.addType(6, "estFlow", {{"motion.deltaX", UsdType::kInt16}, {"motion.deltaY", UsdType::kInt16}});
  const std::size_t baro = log.addType(8, "estBarometer", {{"baro.asl", F}});
  const std::size_t pose = log.addType(
      9, "estPose",
      {{"locSrv.x", F}, {"locSrv.y", F}, {"locSrv.z", F}, {"locSrv.qx", F}, {"locSrv.qy", F}, {"locSrv.qz", F}, {"locSrv.qw", F}});
  const std::size_t yaw = log.addType(1000, "estYawError", {{"yawError", F}});
  // t0 = 5 000 µs: the first event of any type.
  log.addEvent(acc, 5000, {-0.004290993, 0.003523335, 0.9990389});
  log.addEvent(gyro, 5016, {0.03240617, 0.05542586, -0.04069845});
  log.addEvent(tdoa, 8155, {0, 1, -2.18167});
  log.addEvent(baro, 5040, {176.4099});
  log.addEvent(pose, 7728, {1.495, 0.035, 0.029, -0.004151312, 0.001383771, -0.01660525, 0.9998525});
  log.addEvent(acc, 6000, {-0.00415879, 0.003383534, 0.9992763});
  log.addEvent(gyro, 6011, {0.0292956, 0.0605188, -0.04218704});
  log.addEvent(tdoa, 11878, {3, 4, 1.70311});
  log.addEvent(tof, 24464, {16});
  log.addEvent(flow, 1144054, {0, 8});
  log.addEvent(tof, 67764, {15});
  log.addEvent(flow, 1153942, {3, -4});
  log.addEvent(baro, 6031, {176.41});
  log.addEvent(pose, 14331, {1.495, 0.035, 0.029, -0.006918853, 0.005535082, -0.01383771, 0.999865});
  log.addEvent(yaw, 9000, {0.5});
  if (version == 1) {  // version 1 holds whole milliseconds: floor every stamp to a millisecond
    log.version = 1;
    for (auto& s : log.events)
      for (auto& t : s.t_us) t = (t / 1000) * 1000;
  }
  return log;
}

/// The bytes of a log with event `number`'s bytes changed by `edit`, CRC recomputed.
std::string edited(const std::string& bytes, const std::function<void(std::string&)>& edit) {
  std::string body = bytes.substr(0, bytes.size() - 4);
  edit(body);
  const std::uint32_t crc = crc32(body);
  for (int i = 0; i < 4; ++i) body.push_back(static_cast<char>((crc >> (8 * i)) & 0xFF));
  return body;
}

/// The message of the InputError that parsing `bytes` (then importing) throws; "" when none.
std::string importError(const std::string& bytes, const UsdReadOptions& options = {}) {
  try {
    (void)flightFromUsdLog(parseUsdLog(bytes, "t.log", options));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// ------------------------------------------------------------------------------------------------ reader/writer

TEST(UsdLog, WriterAndReaderAgreeOnEveryFieldType) {
  // GIVEN a log with one field of each type, values at the edges of their ranges
  UsdLog log;
  log.source = "types.log";
  const std::size_t t = log.addType(65535, "allTypes",
                                    {{"u8", UsdType::kUint8}, {"i8", UsdType::kInt8}, {"u16", UsdType::kUint16},
                                     {"i16", UsdType::kInt16}, {"u32", UsdType::kUint32}, {"i32", UsdType::kInt32},
                                     {"f", UsdType::kFloat}, {"e", UsdType::kHalf}});
  const std::vector<double> a{255, -128, 65535, -32768, 4294967295.0, -2147483648.0, 0.1, -1.5};
  const std::vector<double> b{0, 127, 1, 32767, 0, 2147483647.0, -3.25e7, 6.103515625e-05};
  log.addEvent(t, 1, a);
  log.addEvent(t, std::uint64_t{1} << 40, b);
  // WHEN it is written and read back
  UsdReadReport report;
  const std::string bytes = formatUsdLog(log);
  const UsdLog back = parseUsdLog(bytes, "types.log", {}, &report);
  // THEN the header, stamps and every value survive (floats rounded to float32, halves exact here)
  EXPECT_TRUE(report.crc_ok);
  EXPECT_EQ(report.n_events, 2u);
  EXPECT_EQ(report.n_bytes, bytes.size());
  ASSERT_EQ(back.types.size(), 1u);
  EXPECT_EQ(back.types[0].id, 65535);
  EXPECT_EQ(back.types[0].payload_bytes, 1u + 1 + 2 + 2 + 4 + 4 + 4 + 2);
  EXPECT_EQ(back.events[0].t_us[1], std::uint64_t{1} << 40);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(back.value(0, 0, k), k == 6 ? f32(a[k]) : a[k]) << back.types[0].fields[k].name;
    EXPECT_EQ(back.value(0, 1, k), k == 6 ? f32(b[k]) : b[k]) << back.types[0].fields[k].name;
  }
  // AND writing what was read gives the same bytes
  EXPECT_EQ(formatUsdLog(back), bytes);
  // AND values that do not fit their type are refused when building
  EXPECT_THROW(log.addEvent(t, 2, {256, 0, 0, 0, 0, 0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(log.addEvent(t, 2, {1.5, 0, 0, 0, 0, 0, 0, 0}), std::invalid_argument);
}

TEST(UsdLog, HalfFloatsDecodeExactlyAndRoundToNearest) {
  UsdLog log;
  const std::size_t t = log.addType(1, "h", {{"e", UsdType::kHalf}});
  const std::vector<double> exact{0.0, 1.0, -2.0, 65504.0, 5.960464477539063e-08 /* smallest subnormal */, 0.333251953125};
  for (std::size_t i = 0; i < exact.size(); ++i) log.addEvent(t, i, {exact[i]});
  log.addEvent(t, 10, {1.0 + 1.0 / 4096.0});  // halfway between 1 and 1 + 2^-10: ties to even (1.0)
  log.addEvent(t, 11, {1e6});                 // beyond the largest half: +Inf
  const UsdLog back = parseUsdLog(formatUsdLog(log), "h.log");
  for (std::size_t i = 0; i < exact.size(); ++i) EXPECT_EQ(back.value(0, i, 0), exact[i]);
  EXPECT_EQ(back.value(0, exact.size(), 0), 1.0);
  EXPECT_EQ(back.value(0, exact.size() + 1, 0), std::numeric_limits<double>::infinity());
}

TEST(UsdLog, Crc32IsZlibs) {
  // The standard check value of CRC-32 (IEEE 802.3, reflected): crc32("123456789") = 0xCBF43926.
  EXPECT_EQ(crc32("123456789"), 0xCBF43926u);
  EXPECT_EQ(crc32(""), 0u);
}

TEST(UsdLog, EqualTimestampsAreCountedAndNoted) {
  UsdLog log;
  const std::size_t t = log.addType(1, "estBarometer", {{"baro.asl", F}});
  log.addEvent(t, 10, {1.0});
  log.addEvent(t, 10, {2.0});
  log.addEvent(t, 10, {3.0});
  UsdReadReport report;
  (void)parseUsdLog(formatUsdLog(log), "dup.log", {}, &report);
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_EQ(report.notes[0], "2 events of estBarometer share a timestamp with the previous one");
}

// ------------------------------------------------------------------------------------------------ errors

TEST(UsdLogErrors, EachBadInputNamesFileByteEventAndField) {
  const UsdLog log = utilStyleLog();
  const std::string good = formatUsdLog(log);
  const int tdoa = log.typeIndex("estTDOA");
  const std::size_t tdoa1 = log.events[tdoa].offset[1];  // second estTDOA event (event 7)
  EXPECT_EQ(log.events[tdoa].number[1], 7u);

  EXPECT_EQ(importError(""), "t.log: byte 0 (magic): empty file; expected a uSD-card deck event log (first byte 0xBC)");
  EXPECT_EQ(importError("t_tdoa,idA\n"),
            "t.log: byte 0 (magic): bad magic byte 0x74; expected 0xBC (not a uSD-card deck event log)");
  EXPECT_EQ(importError(edited(good, [](std::string& b) { b[1] = 3; })),
            "t.log: byte 1 (version): unsupported format version 3 (this reader knows versions 1 and 2)");
  // An event id the header does not declare.
  EXPECT_EQ(importError(edited(good, [&](std::string& b) { b[tdoa1] = 42; })),
            fmt::format("t.log: byte {}, event 7 (id): event id 42 is not declared in the header (declared: 3 "
                        "estAcceleration, 4 estGyroscope, 5 estTOF, 6 estFlow, 7 estTDOA, 8 estBarometer, 9 estPose, "
                        "1000 estYawError)",
                        tdoa1));
  // A last event cut inside its payload (the CRC still valid: a writer that stopped mid-event).
  const std::size_t last = good.size() - 4;  // the CRC trailer starts here
  const std::size_t last_event = log.events[log.typeIndex("estYawError")].offset[0];
  EXPECT_EQ(importError(edited(good, [&](std::string& b) { b.resize(last - 2); })),
            fmt::format("t.log: byte {}, event 14 (estYawError.yawError): truncated event: its payload needs 4 bytes, "
                        "2 left",
                        last_event));
  EXPECT_EQ(importError(edited(good, [&](std::string& b) { b.resize(last_event + 5); })),
            fmt::format("t.log: byte {}, event 14 (timestamp): truncated event: 5 bytes left, an event header needs 10",
                        last_event));
  // A damaged byte: the CRC does not match.
  std::string damaged = good;
  damaged[tdoa1 + 12] ^= 0x40;
  EXPECT_EQ(importError(damaged).rfind(fmt::format("t.log: byte {} (crc): CRC mismatch: stored 0x", last), 0), 0u)
      << importError(damaged);
  // Time going backwards within one event type (the second estTDOA stamped before the first).
  EXPECT_EQ(importError(edited(good, [&](std::string& b) {
              for (int i = 0; i < 8; ++i) b[tdoa1 + 2 + i] = i == 0 ? 1 : 0;
            })),
            fmt::format("t.log: byte {}, event 7 (estTDOA.timestamp): time goes backwards within estTDOA: 1 µs after "
                        "8155 µs",
                        tdoa1));
  // A value the flight CSV would refuse: NaN.
  EXPECT_EQ(importError(edited(good, [&](std::string& b) {
              const float nan = std::numeric_limits<float>::quiet_NaN();
              std::memcpy(&b[tdoa1 + 10 + 2], &nan, 4);
            })),
            fmt::format("t.log: byte {}, event 7 (estTDOA.distanceDiff): NaN or Inf is not allowed", tdoa1));
}

TEST(UsdLogErrors, MalformedHeadersAreLocated) {
  // GIVEN hand-written headers: magic, version 2, one event type with id 1 named "e"
  const auto header = [](const std::string& fields_and_count) {
    std::string b("\xBC\x02\x00\x01\x00\x01\x00" "e\x00", 9);
    b += fields_and_count;
    return b;
  };
  const auto withCrc = [](std::string b) {
    const std::uint32_t crc = crc32(b);
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<char>((crc >> (8 * i)) & 0xFF));
    return b;
  };
  EXPECT_EQ(importError(withCrc(header(std::string("\x01\x00x(q)\x00", 7)))),
            "t.log: byte 11 (e field 0): 'x(q)' is not name(T) with T one of B b H h I i f e");
  EXPECT_EQ(importError(withCrc(header(std::string("\x01\x00x(f", 5)))),
            "t.log: byte 11 (e field 0): unterminated string (no NUL byte before the end of the header)");
  EXPECT_EQ(importError(withCrc(header(std::string("\x02\x00x(f)\x00x(B)\x00", 12)))),
            "t.log: byte 5 (e): field 'x' of e is declared twice");
  // Two event types with the same id.
  std::string two("\xBC\x02\x00\x02\x00\x01\x00" "a\x00\x00\x00\x01\x00" "b\x00\x00\x00", 17);
  EXPECT_EQ(importError(withCrc(two)), "t.log: byte 11 (b): event id 1 is declared twice (a and b)");
  // A log without any event of the flight layout.
  EXPECT_EQ(importError(withCrc(header(std::string("\x00\x00", 2)))),
            "t.log: no event of the flight layout carries data (known: estTDOA, estDistance, estAcceleration, "
            "estGyroscope, estTOF, estFlow, estBarometer, estPose, estPosition; see docs/io.md §6)");
}

TEST(UsdLogErrors, AnchorIdsAndQuaternionsAreCheckedAsTheCsvReaderDoes) {
  UsdLog log;
  const std::size_t t = log.addType(1, "estTDOA", {{"idA", UsdType::kUint16}, {"idB", UsdType::kUint8}, {"distanceDiff", F}});
  log.addEvent(t, 0, {300, 1, 0.5});
  // header: 5 + id 2 + "estTDOA\0" 8 + count 2 + "idA(H)\0" 7 + "idB(B)\0" 7 + "distanceDiff(f)\0" 16 = 47
  EXPECT_EQ(log.events[0].offset[0], 47u);
  EXPECT_EQ(importError(formatUsdLog(log)),
            "t.log: byte 47, event 0 (estTDOA.idA): anchor id must be an integer in [0, 255]: 300");
  UsdLog q;
  const std::size_t p = q.addType(
      2, "estPose",
      {{"locSrv.x", F}, {"locSrv.y", F}, {"locSrv.z", F}, {"locSrv.qx", F}, {"locSrv.qy", F}, {"locSrv.qz", F}, {"locSrv.qw", F}});
  q.addEvent(p, 0, {0, 0, 0, 0, 0, 0, 0.5});
  EXPECT_NE(importError(formatUsdLog(q)).find("(estPose.locSrv.qx): pose quaternion is far from unit norm: |q| = 0.5"),
            std::string::npos)
      << importError(formatUsdLog(q));
  // A compressed quaternion whose three small components are too large to leave room for the largest.
  UsdLog c;
  const std::size_t cp = c.addType(3, "estPose", {{"x", F}, {"y", F}, {"z", F}, {"quat", UsdType::kUint32}});
  c.addEvent(cp, 0, {0, 0, 0, double((3u << 30) | (511u << 20) | (511u << 10) | 511u)});
  EXPECT_NE(importError(formatUsdLog(c)).find("(estPose.quat): pose quaternion is far from unit norm: |q| = 1.22474"),
            std::string::npos)
      << importError(formatUsdLog(c));
}

TEST(UsdLogErrors, SalvageReadsACutLogUpToTheLastCompleteEvent) {
  // GIVEN a log whose writing stopped in the middle of an event (no CRC trailer)
  const UsdLog log = utilStyleLog();
  const std::string good = formatUsdLog(log);
  const std::size_t tdoa1 = log.events[log.typeIndex("estTDOA")].offset[1];
  const std::string cut = good.substr(0, tdoa1 + 7);
  // WHEN read normally THEN the CRC check refuses it
  EXPECT_NE(importError(cut).find("(crc): CRC mismatch"), std::string::npos);
  // WHEN read in salvage mode THEN the 7 complete events before it are kept and the loss is noted
  UsdReadOptions salvage;
  salvage.salvage = true;
  UsdReadReport report;
  const UsdLog back = parseUsdLog(cut, "cut.log", salvage, &report);
  EXPECT_FALSE(report.crc_ok);
  EXPECT_EQ(report.n_events, 7u);
  ASSERT_EQ(report.notes.size(), 2u);
  EXPECT_NE(report.notes[1].find("the last 7 bytes (a truncated event 7) are ignored"), std::string::npos) << report.notes[1];
  const Flight f = flightFromUsdLog(back);
  EXPECT_EQ(f.tdoa.size(), 1u);
  EXPECT_EQ(f.acc.size(), 2u);
}

// ------------------------------------------------------------------------------------------------ import

TEST(UsdImport, EveryValueArrivesInTheFlightCsvWithUtilUnits) {
  // GIVEN a log in the UTIL recording layout, written to a file
  test::TempDir dir;
  const UsdLog log = utilStyleLog();
  const std::string path = dir.file("flight.log");
  writeUsdLog(log, path);
  // WHEN it is imported
  UsdImportReport report;
  const Flight f = importUsdLog(path, {}, &report);
  // THEN every stream holds the logged values in the flight's units, on a clock that starts at the first event
  EXPECT_EQ(report.t0_us, 5000.0);
  ASSERT_EQ(f.tdoa.size(), 2u);
  EXPECT_EQ(f.tdoa[0].t_s, 3155.0 / 1e6);
  EXPECT_EQ(f.tdoa[1].id_a, 3);
  EXPECT_EQ(f.tdoa[1].id_b, 4);
  EXPECT_EQ(f.tdoa[1].tdoa_m, f32(1.70311));
  ASSERT_EQ(f.acc.size(), 2u);
  EXPECT_EQ(f.acc[0].t_s, 0.0);
  EXPECT_EQ(f.acc[1].t_s, 0.001);
  EXPECT_EQ(f.acc[0].b_value.z(), f32(0.9990389) * kGravity_mps2);
  ASSERT_EQ(f.gyro.size(), 2u);
  EXPECT_EQ(f.gyro[1].b_value.y(), f32(0.0605188) * kDegToRad);
  ASSERT_EQ(f.tof.size(), 2u);
  EXPECT_EQ(f.tof[0].value, 0.016);  // 16 mm
  EXPECT_EQ(f.tof[1].t_s, 62764.0 / 1e6);
  ASSERT_EQ(f.flow.size(), 2u);
  EXPECT_EQ(f.flow[1].delta_x, 3.0);
  EXPECT_EQ(f.flow[1].delta_y, -4.0);
  ASSERT_EQ(f.baro.size(), 2u);
  EXPECT_EQ(f.baro[1].value, f32(176.41));
  ASSERT_EQ(f.pose.size(), 2u);
  EXPECT_TRUE(f.pose_has_orientation);
  EXPECT_EQ(f.pose[1].w_p_b.x(), f32(1.495));
  EXPECT_EQ(f.pose[1].w_q_b.w(), f32(0.999865));
  EXPECT_EQ(f.pose[1].w_q_b.x(), f32(-0.006918853));
  EXPECT_EQ(f.columns, utilTdoaColumns());
  EXPECT_TRUE(f.twr.empty());
  // AND the event type outside the layout is noted, not dropped silently
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_EQ(report.notes[0], "estYawError (1 events) is not part of the flight layout: ignored");
  ASSERT_EQ(report.sources.size(), 7u);
  EXPECT_EQ(report.sources[0].event, "estTDOA");
  EXPECT_EQ(report.sources[0].fields, "idA, idB, distanceDiff");
  // AND the flight CSV written from it reads back as the same flight, bit for bit
  const std::string csv = dir.file("flight.csv");
  writeFlightCsv(f, csv);
  EXPECT_TRUE(test::flightsIdentical(f, readFlightCsv(csv)));
}

TEST(UsdImport, VersionOneStampsAreMilliseconds) {
  const UsdLog log = utilStyleLog(1);
  const std::string bytes = formatUsdLog(log);
  const Flight f = flightFromUsdLog(parseUsdLog(bytes, "v1.log"));
  // t0 = 5 ms; the first TDoA at 8 ms, the second flow event at 1153 ms.
  EXPECT_EQ(f.tdoa[0].t_s, 0.003);
  EXPECT_EQ(f.flow[1].t_s, 1.148);
  // 6 bytes of event header per event instead of 10.
  EXPECT_EQ(formatUsdLog(utilStyleLog(2)).size() - bytes.size(), 15u * 4u);
}

TEST(UsdImport, AlternativeRecordingsOfTofPoseAndTwr) {
  // GIVEN the current firmware's payloads: estTOF {distance [m]}, estPose {x, y, z, quat (compressed)}, TWR
  UsdLog log;
  log.source = "new.log";
  const std::size_t tof = log.addType(1, "estTOF", {{"distance", F}});
  const std::size_t pose = log.addType(2, "estPose", {{"x", F}, {"y", F}, {"z", F}, {"quat", UsdType::kUint32}});
  const std::size_t twr = log.addType(3, "estDistance", {{"id", UsdType::kUint8}, {"distance", F}});
  const std::size_t empty_pos = log.addType(4, "estPosition", {{"source", UsdType::kUint8}});
  log.addEvent(tof, 0, {0.75});
  // Identity: largest component w (index 3), the others 0.
  log.addEvent(pose, 100, {1, 2, 3, double(3u << 30)});
  // 90° about z: (x, y, z, w) = (0, 0, √½, √½); largest index 2 (z), w stored with magnitude 511.
  log.addEvent(pose, 200, {1, 2, 3, double((2u << 30) | 511u)});
  log.addEvent(twr, 300, {5, 2.5});
  log.addEvent(empty_pos, 400, {1});
  UsdImportReport report;
  const Flight f = flightFromUsdLog(log, &report);
  // THEN each lands in its stream
  ASSERT_EQ(f.tof.size(), 1u);
  EXPECT_EQ(f.tof[0].value, 0.75);
  ASSERT_EQ(f.pose.size(), 2u);
  EXPECT_TRUE(f.pose_has_orientation);
  EXPECT_EQ(f.pose[0].w_q_b.coeffs(), Quat::Identity().coeffs());
  EXPECT_NEAR(f.pose[1].w_q_b.z(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(f.pose[1].w_q_b.w(), std::sqrt(0.5), 1e-15);
  EXPECT_EQ(f.pose[1].w_q_b.x(), 0.0);
  ASSERT_EQ(f.twr.size(), 1u);
  EXPECT_EQ(f.twr[0].anchor_id, 5);
  EXPECT_EQ(f.twr[0].range_m, 2.5);
  EXPECT_EQ(f.columns.front(), "t_twr");
  // AND estPosition without coordinates is noted (the pose came from estPose)
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_EQ(report.notes[0], "estPosition (1 events) is not part of the flight layout: ignored");
  // AND the CSV round trip holds with TWR and compressed quaternions too
  test::TempDir dir;
  writeFlightCsv(f, dir.file("f.csv"));
  EXPECT_TRUE(test::flightsIdentical(f, readFlightCsv(dir.file("f.csv"))));
}

TEST(UsdImport, KnownEventWithoutItsFieldsIsNoted) {
  UsdLog log;
  log.source = "bare.log";
  const std::size_t tof = log.addType(1, "estTOF", {});  // the firmware event without added log variables
  const std::size_t baro = log.addType(2, "estBarometer", {{"baro.asl", F}});
  log.addEvent(tof, 0, {});
  log.addEvent(baro, 0, {100.0});
  UsdImportReport report;
  const Flight f = flightFromUsdLog(log, &report);
  EXPECT_TRUE(f.tof.empty());
  ASSERT_EQ(report.notes.size(), 1u);
  EXPECT_EQ(report.notes[0], "estTOF (1 events) lacks the fields of the tof stream: expected {range.zrange} or {distance}");
}

TEST(UsdImport, RealUtilFlightSurvivesTheRoundTripThroughEvents) {
  // GIVEN the first 3 s of a real UTIL flight (all 8 streams' worth of columns, 7 non-empty)
  const auto path = test::pilotFlight("0425-traj5");
  UWB_REQUIRE_REAL_DATA(path);
  const Flight original = sliceFlight(readFlightCsv(path->string()), 0.0, 3.0);
  ASSERT_GT(original.tdoa.size(), 500u);
  ASSERT_GT(original.pose.size(), 300u);
  // WHEN its streams are written as the events UTIL recorded, and imported
  const UsdLog log = usdLogFromFlight(original);
  const Flight back = flightFromUsdLog(parseUsdLog(formatUsdLog(log), "roundtrip.log"));
  // THEN every stream has every sample: times exact (µs stamps of %.6f times), ids exact, tof exact (mm),
  // flow exact (counts), other values within float32 precision of the CSV's decimals
  const auto close = [](double a, double b) { return std::abs(a - b) <= 6e-8 * std::abs(b) + 1e-300; };
  ASSERT_EQ(back.tdoa.size(), original.tdoa.size());
  for (std::size_t i = 0; i < original.tdoa.size(); ++i) {
    const auto &a = back.tdoa[i], &b = original.tdoa[i];
    ASSERT_TRUE(a.t_s == b.t_s && a.id_a == b.id_a && a.id_b == b.id_b && close(a.tdoa_m, b.tdoa_m)) << "tdoa " << i;
  }
  const auto imu = [&](const std::vector<ImuSample>& a, const std::vector<ImuSample>& b, const char* name) {
    ASSERT_EQ(a.size(), b.size()) << name;
    for (std::size_t i = 0; i < b.size(); ++i) {
      ASSERT_TRUE(a[i].t_s == b[i].t_s && close(a[i].b_value.x(), b[i].b_value.x()) &&
                  close(a[i].b_value.y(), b[i].b_value.y()) && close(a[i].b_value.z(), b[i].b_value.z()))
          << name << " " << i;
    }
  };
  imu(back.acc, original.acc, "acc");
  imu(back.gyro, original.gyro, "gyro");
  ASSERT_EQ(back.tof.size(), original.tof.size());
  for (std::size_t i = 0; i < original.tof.size(); ++i) {
    ASSERT_TRUE(back.tof[i].t_s == original.tof[i].t_s && back.tof[i].value == original.tof[i].value) << "tof " << i;
  }
  ASSERT_EQ(back.flow.size(), original.flow.size());
  for (std::size_t i = 0; i < original.flow.size(); ++i) {
    const auto &a = back.flow[i], &b = original.flow[i];
    ASSERT_TRUE(a.t_s == b.t_s && a.delta_x == b.delta_x && a.delta_y == b.delta_y) << "flow " << i;
  }
  ASSERT_EQ(back.baro.size(), original.baro.size());
  for (std::size_t i = 0; i < original.baro.size(); ++i) {
    ASSERT_TRUE(back.baro[i].t_s == original.baro[i].t_s && close(back.baro[i].value, original.baro[i].value)) << i;
  }
  ASSERT_EQ(back.pose.size(), original.pose.size());
  EXPECT_TRUE(back.pose_has_orientation);
  for (std::size_t i = 0; i < original.pose.size(); ++i) {
    const auto &a = back.pose[i], &b = original.pose[i];
    bool same = a.t_s == b.t_s;
    for (int k = 0; k < 3; ++k) same = same && close(a.w_p_b[k], b.w_p_b[k]);
    for (int k = 0; k < 4; ++k) same = same && close(a.w_q_b.coeffs()[k], b.w_q_b.coeffs()[k]);
    ASSERT_TRUE(same) << "pose " << i;
  }
  // AND the imported flight's CSV reads back as the same flight
  EXPECT_TRUE(test::flightsIdentical(back, parseFlightCsv(formatFlightCsv(back), "roundtrip.csv")));
}

TEST(UsdDeckConfig, TheShippedConfigNamesOnlyWhatImportReadsAndItsLogImports) {
  // GIVEN examples/usd/config.txt, read as the uSD deck's firmware reads it
  const test::UsdDeckConfig config = test::readShippedUsdConfig();
  EXPECT_EQ(config.version, 1);  // the only version the firmware accepts
  EXPECT_GE(config.buffer_bytes, 1024);
  EXPECT_LE(config.file_prefix.size(), 10u);  // the firmware's 13-byte name holds the prefix and two digits
  std::vector<std::string> events;
  for (const auto& e : config.events) events.push_back(e.first);
  EXPECT_EQ(events, (std::vector<std::string>{"estTDOA", "estAcceleration", "estGyroscope", "estTOF", "estPose"}));
  // THEN every event and variable it names is one that import reads: payload + variables are a recording's fields
  const std::vector<UsdRecording> table = usdRecordings();
  for (const auto& [event, variables] : config.events) {
    std::vector<std::string> fields = test::firmwarePayload(event);
    fields.insert(fields.end(), variables.begin(), variables.end());
    const bool read = std::any_of(table.begin(), table.end(), [&](const UsdRecording& r) {
      return r.event == event && r.fields == fields;
    });
    EXPECT_TRUE(read) << event << " with " << fields.size() << " fields is not a recording import reads";
    for (const std::string& v : variables) {
      const bool known = std::any_of(table.begin(), table.end(), [&](const UsdRecording& r) {
        return r.event == event && std::find(r.fields.begin(), r.fields.end(), v) != r.fields.end();
      });
      EXPECT_TRUE(known) << event << " variable " << v;
    }
  }
  // AND a log written with exactly those names (the utilStyleLog flight through the config) imports: TDoA, IMU,
  // downward range and the mocap pose with its orientation, nothing left out
  const Flight flight = flightFromUsdLog(utilStyleLog());
  const UsdLog log = test::usdLogThroughConfig(flight, config);
  EXPECT_EQ(log.types.size(), 5u);
  UsdImportReport report;
  const Flight back = flightFromUsdLog(parseUsdLog(formatUsdLog(log), "config.log"), &report);
  EXPECT_EQ(back.tdoa.size(), 2u);
  EXPECT_EQ(back.acc.size(), 2u);
  EXPECT_EQ(back.gyro.size(), 2u);
  EXPECT_EQ(back.tof.size(), 2u);
  EXPECT_EQ(back.pose.size(), 2u);
  EXPECT_TRUE(back.pose_has_orientation);
  EXPECT_TRUE(report.notes.empty()) << report.notes.front();
  EXPECT_EQ(report.sources.size(), 5u);
}

// ------------------------------------------------------------------------------------------------ CLI

class ImportCli : public ::testing::Test {
 protected:
  void SetUp() override {
    UWB_REQUIRE_CLI();
  }
  test::TempDir dir_;
};

TEST_F(ImportCli, JsonSummaryAndAFlightTheOtherCommandsRead) {
  // GIVEN a log with every stream but TWR
  UsdLog log = utilStyleLog();
  const std::string in = dir_.file("in.log");
  writeUsdLog(log, in);
  const std::string out = dir_.file("out.csv");
  // WHEN imported with --json
  const test::CliResult r = test::runCli("import " + in + " --out " + out + " --json");
  // THEN one JSON object with the counts and sources, and the CSV equals the library's import
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("format_version"), 2);
  EXPECT_EQ(j.at("n_events"), 15);
  EXPECT_TRUE(j.at("crc_ok").get<bool>());
  EXPECT_EQ(j.at("streams").at("tdoa").at("count"), 2);
  EXPECT_EQ(j.at("streams").at("tdoa").at("event"), "estTDOA");
  EXPECT_NEAR(j.at("streams").at("acc").at("rate_hz").get<double>(), 1000.0, 1e-9);
  EXPECT_EQ(j.at("notes").size(), 1u);
  EXPECT_TRUE(test::flightsIdentical(readFlightCsv(out), importUsdLog(in)));
}

TEST_F(ImportCli, MissingStreamsAreWarningsAndBadLogsExitWithTheLocatedError) {
  // GIVEN a log with only a barometer
  UsdLog log;
  const std::size_t b = log.addType(1, "estBarometer", {{"baro.asl", F}});
  log.addEvent(b, 0, {100.0});
  const std::string in = dir_.file("baro.log");
  writeUsdLog(log, in);
  const test::CliResult r = test::runCli("import " + in + " --out " + dir_.file("b.csv") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const auto warnings = nlohmann::json::parse(r.out).at("warnings");
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_NE(warnings[0].get<std::string>().find("no UWB measurements"), std::string::npos);
  EXPECT_NE(warnings[1].get<std::string>().find("no IMU (acc and gyro missing)"), std::string::npos);
  // AND a damaged log exits 2 with the located message and writes nothing
  std::string bytes = formatUsdLog(log);
  bytes[0] = 'x';
  const std::string bad = dir_.write("bad.log", bytes);
  const test::CliResult e = test::runCli("import " + bad + " --out " + dir_.file("x.csv"));
  EXPECT_EQ(e.exit_code, 2);
  EXPECT_NE(e.err.find(bad + ": byte 0 (magic): bad magic byte 0x78"), std::string::npos) << e.err;
  EXPECT_FALSE(std::filesystem::exists(dir_.file("x.csv")));
}

}  // namespace
}  // namespace uwb
