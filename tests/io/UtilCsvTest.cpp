/** @file UtilCsvTest.cpp
 *  @brief UTIL flight CSV reader/writer: layouts, unit conversion, exact round trip, one test per malformed input,
 *  and every real util-pilot / util-final-extract file (skipped when the data is absent).
 */
#include "uwb/io/UtilCsv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "IoTestHelpers.h"
#include "uwb/core/Error.h"

namespace uwb {
namespace {

using test::TempDir;
using ::testing::HasSubstr;

const std::string kFullHeader =
    "t_tdoa,idA,idB,tdoa_meas,t_acc,acc_x,acc_y,acc_z,t_gyro,gyro_x,gyro_y,gyro_z,t_tof,tof,t_flow,deltaX,deltaY,"
    "t_baro,baro,t_pose,pose_x,pose_y,pose_z,pose_qx,pose_qy,pose_qz,pose_qw\n";

/// Minimal TDoA + position file used by the malformed-input tests.
const std::string kSmallHeader = "t_tdoa,idA,idB,tdoa_meas,t_pose,pose_x,pose_y,pose_z\n";

/// Expects readFlightCsv(text) to throw InputError whose message contains every string in `parts`.
void expectInputError(const std::string& text, const std::vector<std::string>& parts,
                      const FlightReadOptions& options = {}) {
  TempDir dir;
  const std::string path = dir.write("bad.csv", text);
  SCOPED_TRACE("input:\n" + text);
  const std::string msg = test::messageOf<InputError>([&] { (void)readFlightCsv(path, options); });
  EXPECT_THAT(msg, HasSubstr(path)) << "message must name the file";
  for (const auto& p : parts) EXPECT_THAT(msg, HasSubstr(p));
}

// ------------------------------------------------------------------------------------------------ layouts

TEST(UtilCsv, ReadsFullLayoutWithStreamsOfDifferentLengthsAndConvertsUnits) {
  // GIVEN a 27-column file where acc/gyro run 3 rows, TDoA 2, pose 1, ToF/flow/baro 1
  TempDir dir;
  const std::string path = dir.write(
      "f.csv", kFullHeader +
                   "0.001,1,2,0.5,0.000,0,0,1,0.0001,10,0,-90,0.04,0.019,1.17,21,-3,0.00004,180.5,0.0003,1.496,0.037,"
                   "0.029,0,0,0,1\n"
                   "0.005,2,3,-0.25,0.001,0.5,-1,1,0.0011,0,180,0,,,,,,,,,,,,,,,\n"
                   ",,,,0.002,0,0,2,0.0021,1,2,3,,,,,,,,,,,,,,,\n");
  // WHEN it is read
  ReadReport report;
  const Flight f = readFlightCsv(path, {}, &report);
  // THEN every stream has its own length, and acc/gyro are in SI
  ASSERT_EQ(test::streamSizes(f),
            (test::StreamSizes{.tdoa = 2, .twr = 0, .acc = 3, .gyro = 3, .tof = 1, .flow = 1, .baro = 1, .pose = 1}));
  EXPECT_TRUE(f.pose_has_orientation);
  EXPECT_EQ(f.tdoa[1].id_a, 2);
  EXPECT_EQ(f.tdoa[1].id_b, 3);
  EXPECT_DOUBLE_EQ(f.tdoa[1].tdoa_m, -0.25);
  EXPECT_DOUBLE_EQ(f.acc[0].b_value.z(), kGravity_mps2);
  EXPECT_DOUBLE_EQ(f.acc[1].b_value.y(), -kGravity_mps2);
  EXPECT_DOUBLE_EQ(f.gyro[0].b_value.z(), -kPi / 2.0);
  EXPECT_DOUBLE_EQ(f.gyro[1].b_value.y(), kPi);
  EXPECT_DOUBLE_EQ(f.flow[0].delta_x, 21.0);
  EXPECT_DOUBLE_EQ(f.pose[0].w_q_b.w(), 1.0);
  EXPECT_EQ(f.columns.size(), 27u);
  EXPECT_EQ(report.n_rows, 3u);
  EXPECT_EQ(report.n_bytes, std::filesystem::file_size(path));
}

TEST(UtilCsv, ReadsExtractLayoutAsPositionOnlyPose) {
  TempDir dir;
  const std::string path = dir.write("e.csv", kSmallHeader +
                                                  "0.001104,6,7,0.7084563,0.001784,1.488,-0.067,0.08\n"
                                                  "0.002745,7,0,0.1313694,,,,\n");
  ReadReport report;
  const Flight f = readFlightCsv(path, {}, &report);
  EXPECT_EQ(f.tdoa.size(), 2u);
  ASSERT_EQ(f.pose.size(), 1u);
  EXPECT_FALSE(f.pose_has_orientation);
  EXPECT_TRUE(f.pose[0].w_q_b.isApprox(Quat::Identity()));
  EXPECT_TRUE(f.acc.empty());
  EXPECT_THAT(report.notes, ::testing::Contains(HasSubstr("position only")));
}

TEST(UtilCsv, ReadsTwrVariantAndColumnsInAnyOrder) {
  const Flight f = test::readFlightText(TempDir(), "t.csv",
                                        "t_twr,anchor_id,twr_range,t_pose,pose_z,pose_y,pose_x\n"
                                        "0.01,3,2.5,0.0,1,2,3\n"
                                        "0.02,4,2.75,,,,\n");
  ASSERT_EQ(f.twr.size(), 2u);
  EXPECT_EQ(f.twr[1].anchor_id, 4);
  EXPECT_DOUBLE_EQ(f.twr[1].range_m, 2.75);
  ASSERT_EQ(f.pose.size(), 1u);
  EXPECT_EQ(f.pose[0].w_p_b, Vec3(3, 2, 1));
}

TEST(UtilCsv, ToleratesCrlfSpacesAndTrailingBlankLines) {
  TempDir dir;
  const std::string path = dir.write("c.csv", "t_tdoa, idA ,idB,tdoa_meas\r\n 0.1 ,1,2, 0.5\r\n\r\n\n");
  const Flight f = readFlightCsv(path);
  ASSERT_EQ(f.tdoa.size(), 1u);
  EXPECT_DOUBLE_EQ(f.tdoa[0].t_s, 0.1);
}

TEST(UtilCsv, CountsDuplicateTimestampsAndBlankLinesInNotes) {
  TempDir dir;
  const std::string path =
      dir.write("d.csv", "t_tdoa,idA,idB,tdoa_meas\n0.1,1,2,0.5\n0.1,2,3,0.5\n\n0.2,3,4,0.1\n");
  ReadReport report;
  const Flight f = readFlightCsv(path, {}, &report);
  EXPECT_EQ(f.tdoa.size(), 3u) << "nothing is dropped";
  EXPECT_THAT(report.notes, ::testing::Contains(HasSubstr("1 duplicate timestamp(s) in stream tdoa")));
  EXPECT_THAT(report.notes, ::testing::Contains(HasSubstr("1 blank line(s)")));
}

TEST(UtilCsv, NotesStreamsWhoseColumnsArePresentButEmpty) {
  TempDir dir;
  const std::string path = dir.write("n.csv", "t_tdoa,idA,idB,tdoa_meas,t_tof,tof\n0.1,1,2,0.5,,\n");
  ReadReport report;
  const Flight f = readFlightCsv(path, {}, &report);
  EXPECT_TRUE(f.tof.empty());
  EXPECT_THAT(report.notes, ::testing::Contains(HasSubstr("stream tof: columns present but no samples")));
}

TEST(UtilCsv, ParsesNumbersBitIdenticallyToFromChars) {
  // GIVEN many decimal spellings (fast path and fallback cases), seed 5
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> mag(-30.0, 30.0);
  std::uniform_int_distribution<int> prec(1, 19);
  std::vector<std::string> texts = {"0",     "-0",   "1e22",  "1e23",  "9007199254740993", "123456789012345678901234",
                                    "0.000000000000000000001", "1.7976931348623157e308", "1.", ".5",
                                    "-.25e+2", "00012.5000", "1E5", "2.2250738585072014e-308"};
  for (int i = 0; i < 20000; ++i) {
    const double x = (rng() % 2 ? 1 : -1) * std::pow(10.0, mag(rng)) * std::uniform_real_distribution<double>(1, 10)(rng);
    char buf[64];
    switch (i % 3) {
      case 0: std::snprintf(buf, sizeof buf, "%.*g", prec(rng), x); break;
      case 1: std::snprintf(buf, sizeof buf, "%.6f", std::fmod(x, 1e6)); break;
      default: std::snprintf(buf, sizeof buf, "%.*e", prec(rng), x); break;
    }
    texts.emplace_back(buf);
  }
  std::string csv = "t_tof,tof\n";
  for (std::size_t i = 0; i < texts.size(); ++i) csv += std::to_string(i) + "," + texts[i] + "\n";
  // WHEN the reader parses them
  const Flight f = parseFlightCsv(csv, "numbers.csv");
  // THEN every value equals std::from_chars bit for bit
  ASSERT_EQ(f.tof.size(), texts.size());
  for (std::size_t i = 0; i < texts.size(); ++i) {
    double expected = 0.0;
    const std::string& t = texts[i];
    std::from_chars(t.data(), t.data() + t.size(), expected);
    EXPECT_TRUE(test::sameBits(f.tof[i].value, expected)) << t;
  }
}

// ------------------------------------------------------------------------------------------------ malformed input

/// A malformed file that is one InputError naming its place: the file's text and the parts of the message.
struct MalformedCase {
  const char* name;
  std::string text;
  std::vector<std::string> parts;
};

const std::vector<MalformedCase> kMalformedCases = {
    {"EmptyFileIsMissingHeader", "", {":1", "missing header"}},
    {"DataWithoutHeaderIsMissingHeader", "0.001,1,2,0.5\n0.002,2,3,0.5\n", {":1:1", "missing header"}},
    {"UnknownColumnIsNamed", "t_tdoa,idA,idB,tdoa_meas,pose_roll\n",
     {":1:5 (pose_roll)", "unknown column 'pose_roll'"}},
    {"DuplicatedColumnIsNamed", "t_tdoa,idA,idB,tdoa_meas,idA\n", {":1:5 (idA)", "duplicated column 'idA'"}},
    {"IncompleteStreamColumns", "t_tdoa,idA,idB\n0.1,1,2\n", {":1:", "'tdoa' is incomplete", "tdoa_meas"}},
    {"IncompletePoseQuaternion", "t_pose,pose_x,pose_y,pose_z,pose_qx,pose_qw\n",
     {":1:", "quaternion is incomplete", "pose_qy"}},
    {"NonNumericCell", kSmallHeader + "0.1,1,2,0.5,0.1,1,2,3\n0.2,1,2,abc,0.2,1,2,3\n",
     {":3:4 (tdoa_meas)", "not a number: 'abc'"}},
    {"NaNCell", kSmallHeader + "0.1,1,2,0.5,0.1,nan,2,3\n", {":2:6 (pose_x)", "NaN or Inf"}},
    {"InfCell", kSmallHeader + "0.1,1,2,-inf,0.1,1,2,3\n", {":2:4 (tdoa_meas)", "NaN or Inf"}},
    {"NonIntegerAnchorId", kSmallHeader + "0.1,1.5,2,0.5,0.1,1,2,3\n", {":2:2 (idA)", "anchor id must be an integer"}},
    {"TimeGoingBackwardsWithinAStream", kSmallHeader + "0.1,1,2,0.5,0.3,1,2,3\n0.2,1,2,0.5,0.2,1,2,3\n",
     {":3:5 (t_pose)", "time goes backwards in stream 'pose'"}},
    {"QuaternionFarFromUnitNorm", "t_pose,pose_x,pose_y,pose_z,pose_qx,pose_qy,pose_qz,pose_qw\n0.1,0,0,0,0,0,0,0.5\n",
     {":2:5 (pose_qx)", "far from unit norm"}},
    {"CellAfterTheEndOfAStream", kSmallHeader + "0.1,1,2,0.5,0.1,1,2,3\n0.2,1,2,0.5,,,,\n0.3,1,2,0.5,0.3,1,2,3\n",
     {":4:5 (t_pose)", "continues after it ended", "line 3"}},
    {"PartlyFilledRowWithEmptyTime", kSmallHeader + "0.1,1,2,0.5,,1,,\n",
     {":2:6 (pose_x)", "partly filled row of stream 'pose'"}},
    {"PartlyFilledRowWithEmptyValue", kSmallHeader + "0.1,1,2,,0.1,1,2,3\n", {":2:4 (tdoa_meas)", "partly filled row"}},
    {"RowWithTooFewFields", kSmallHeader + "0.1,1,2,0.5,0.1,1\n", {":2:", "row has 6 fields, the header has 8"}},
    {"RowWithTooManyFields", kSmallHeader + "0.1,1,2,0.5,0.1,1,2,3,4\n",
     {":2:9", "row has 9 fields, the header has 8"}},
    {"NumberOutOfRange", kSmallHeader + "0.1,1,2,1e999,0.1,1,2,3\n", {":2:4 (tdoa_meas)", "out of range"}},
};

class UtilCsvMalformedText : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(UtilCsvMalformedText, IsAnInputErrorNamingTheFileAndThePlace) {
  expectInputError(GetParam().text, GetParam().parts);
}

INSTANTIATE_TEST_SUITE_P(UtilCsvMalformed, UtilCsvMalformedText, ::testing::ValuesIn(kMalformedCases),
                         [](const ::testing::TestParamInfo<MalformedCase>& tested) {
                           return std::string(tested.param.name);
                         });

TEST(UtilCsvMalformed, AnchorIdWithoutSurveyEntry) {
  AnchorSurvey survey;
  survey.source = "mini_survey.txt";
  for (int id = 0; id < 4; ++id) survey.anchors.push_back(Anchor{id, Vec3::Zero(), Quat::Identity()});
  FlightReadOptions options;
  options.survey = &survey;
  expectInputError(kSmallHeader + "0.1,1,2,0.5,0.1,1,2,3\n0.2,2,7,0.5,,,,\n",
                   {":3:3 (idB)", "anchor id 7 has no entry in the survey", "mini_survey.txt"}, options);
}

TEST(UtilCsvMalformed, AnAnchorIdBeyondTheLimitIsAnErrorNotATable) {
  // GIVEN the two-line CSV that made `inspect` allocate gigabytes (a table sized by the largest id)
  expectInputError("t_tdoa,idA,idB,tdoa_meas\n0.1,2147483647,0,0.5\n", {":2:2 (idA)", "[0, 255]", "2147483647"});
  expectInputError("t_tdoa,idA,idB,tdoa_meas\n0.1,0,256,0.5\n", {":2:3 (idB)", "[0, 255]"});
  expectInputError("t_tdoa,idA,idB,tdoa_meas\n0.1,-1,2,0.5\n", {":2:2 (idA)", "[0, 255]"});
  expectInputError("t_tdoa,idA,idB,tdoa_meas\n0.1,1e300,2,0.5\n", {":2:2 (idA)", "[0, 255]"});
}

TEST(UtilCsvMalformed, RequiredStreamWithoutColumns) {
  FlightReadOptions options;
  options.required = {Stream::kTdoa, Stream::kAcc};
  expectInputError(kSmallHeader + "0.1,1,2,0.5,0.1,1,2,3\n", {":1", "required stream 'acc' is missing"}, options);
}

TEST(UtilCsvMalformed, RequiredStreamWithoutSamples) {
  FlightReadOptions options;
  options.required = {Stream::kPose};
  expectInputError(kSmallHeader + "0.1,1,2,0.5,,,,\n", {":2:5 (t_pose)", "required stream 'pose' has no samples"},
                   options);
}

TEST(UtilCsvMalformed, HeaderOnlyFileFailsWhenTdoaIsRequired) {
  FlightReadOptions options;
  options.required = {Stream::kTdoa};
  expectInputError(kSmallHeader, {"required stream 'tdoa' has no samples"}, options);
}

TEST(UtilCsvMalformed, MissingFileIsAFileError) {
  TempDir dir;
  EXPECT_THROW((void)readFlightCsv(dir.file("does_not_exist.csv")), FileError);
}

TEST(UtilCsvMalformed, ErrorCarriesTheLocation) {
  TempDir dir;
  const std::string path = dir.write("loc.csv", kSmallHeader + "0.1,1,2,x,0.1,1,2,3\n");
  const std::optional<InputError> e = test::caught<InputError>([&] { (void)readFlightCsv(path); });
  ASSERT_TRUE(e);
  EXPECT_EQ(e->where().file, path);
  EXPECT_EQ(e->where().line, 2u);
  EXPECT_EQ(e->where().column, 4u);
  EXPECT_EQ(e->where().field, "tdoa_meas");
}

// ------------------------------------------------------------------------------------------------ round trip

/// A synthetic flight in SI units whose values came from "file-like" decimals (as a read flight's do).
Flight syntheticFullFlight(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto dec = [&](double scale) {  // a 7-significant-digit decimal, like the UTIL %.7g values
    std::ostringstream os;
    os.precision(7);
    os << u(rng) * scale;
    return std::stod(os.str());
  };
  Flight f;
  for (int i = 0; i < 40; ++i) f.tdoa.push_back({0.0025 * i, i % 8, (i + 1) % 8, dec(3.0)});
  for (int i = 0; i < 120; ++i) {
    f.acc.push_back({0.001 * i, Vec3(dec(1), dec(1), dec(1)) * kGravity_mps2});
    f.gyro.push_back({0.001 * i + 1e-5, Vec3(dec(300), dec(300), dec(300)) * kDegToRad});
  }
  for (int i = 0; i < 5; ++i) f.tof.push_back({0.04 * i, dec(2)});
  for (int i = 0; i < 9; ++i) f.flow.push_back({0.012 * i, std::round(dec(40)), std::round(dec(40))});
  for (int i = 0; i < 100; ++i) f.baro.push_back({0.001 * i, 180.0 + dec(1)});
  for (int i = 0; i < 30; ++i) {
    f.pose.push_back({0.004 * i, Vec3(dec(2), dec(2), dec(2)), Quat(dec(1), dec(1), dec(1), dec(1)).normalized()});
  }
  f.pose[3].w_p_b.x() = -0.0;  // negative zero survives too
  f.pose_has_orientation = true;
  return f;
}

TEST(UtilCsvRoundTrip, FullLayoutReadWriteReadIsBitExact) {
  // GIVEN a synthetic 27-column flight written once (as if it had been read from a file)
  TempDir dir;
  writeFlightCsv(syntheticFullFlight(7), dir.file("a.csv"));
  const Flight first = readFlightCsv(dir.file("a.csv"));
  // WHEN it is written and read again
  writeFlightCsv(first, dir.file("b.csv"));
  const Flight second = readFlightCsv(dir.file("b.csv"));
  // THEN every value is identical bit for bit, including the converted acc and gyro
  EXPECT_EQ(first.columns, utilTdoaColumns());
  EXPECT_TRUE(test::flightsIdentical(first, second));
  EXPECT_EQ(first.acc.size(), 120u);
}

TEST(UtilCsvRoundTrip, SyntheticFlightFromDecimalsRoundTripsExactlyOnFirstWrite) {
  // acc = d·9.81 and gyro = d·π/180 for decimals d: the writer finds the decimal that reproduces them.
  const Flight original = syntheticFullFlight(11);
  TempDir dir;
  writeFlightCsv(original, dir.file("a.csv"));
  Flight back = readFlightCsv(dir.file("a.csv"));
  back.columns.clear();
  back.source.clear();
  EXPECT_TRUE(test::flightsIdentical(original, back));
}

TEST(UtilCsvRoundTrip, ExtractLayoutKeepsItsColumns) {
  TempDir dir;
  const std::string path = dir.write("e.csv", kSmallHeader +
                                                  "0.001104,6,7,0.7084563,0.001784,1.488,-0.067,0.08\n"
                                                  "0.002745,7,0,0.1313694,0.00219,-0,1e-7,0.08\n"
                                                  "0.004,0,1,-3.5,,,,\n");
  const Flight first = readFlightCsv(path);
  writeFlightCsv(first, dir.file("e2.csv"));
  const Flight second = readFlightCsv(dir.file("e2.csv"));
  EXPECT_TRUE(test::flightsIdentical(first, second));
  EXPECT_FALSE(second.pose_has_orientation);
  std::ifstream in(dir.file("e2.csv"));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header + "\n", kSmallHeader);
}

TEST(UtilCsvRoundTrip, TwrLayout) {
  TempDir dir;
  const Flight first = test::readFlightText(dir, "t.csv",
                                            "t_twr,anchor_id,twr_range,t_acc,acc_x,acc_y,acc_z\n"
                                            "0.01,3,2.5,0,0.01,-0.02,0.999\n"
                                            "0.02,4,2.75,0.001,0.011,-0.021,1.001\n"
                                            ",,,0.002,0.3,0.1,0.7\n");
  writeFlightCsv(first, dir.file("t2.csv"));
  EXPECT_TRUE(test::flightsIdentical(first, readFlightCsv(dir.file("t2.csv"))));
}

TEST(UtilCsvRoundTrip, DefaultColumnsFollowTheStreams) {
  // GIVEN a flight built in code with TWR and position-only pose and no columns
  Flight f;
  f.twr.push_back({0.1, 2, 3.0});
  f.pose.push_back({0.1, Vec3(1, 2, 3), Quat::Identity()});
  f.pose_has_orientation = false;
  TempDir dir;
  writeFlightCsv(f, dir.file("d.csv"));
  const Flight back = readFlightCsv(dir.file("d.csv"));
  EXPECT_EQ(back.columns.front(), "t_twr");
  EXPECT_EQ(back.columns.size(), 3u + 27u - 4u);
  EXPECT_FALSE(back.pose_has_orientation);
  EXPECT_EQ(back.twr.size(), 1u);
}

TEST(UtilCsvRoundTrip, WriterRefusesToDropAStream) {
  Flight f;
  f.columns = {"t_tdoa", "idA", "idB", "tdoa_meas"};
  f.acc.push_back({0.0, Vec3::Zero()});
  EXPECT_THROW((void)formatFlightCsv(f), std::invalid_argument);
  f.columns = {"t_tdoa", "idA", "idB"};
  f.acc.clear();
  EXPECT_THROW((void)formatFlightCsv(f), std::invalid_argument);
}

TEST(UtilCsvRoundTrip, WriterToAnUnwritablePathIsAFileError) {
  TempDir dir;
  EXPECT_THROW(writeFlightCsv(Flight{}, dir.file("no/such/dir/f.csv")), FileError);
}

// ------------------------------------------------------------------------------------------------ real data

std::vector<std::filesystem::path> csvFilesUnder(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  if (!std::filesystem::exists(dir)) return out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().extension() == ".csv" && e.path().filename() != "MANIFEST.csv" &&
        e.path().string().find("survey") == std::string::npos) {
      out.push_back(e.path());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(RealDataUtilCsv, EveryPilotFlightReadsWithItsSurveyAndRoundTrips) {
  UWB_REQUIRE_REAL_DATA(test::pilotFlight("0425-traj1"));
  const auto files = csvFilesUnder(test::realDir() / "util-pilot");
  ASSERT_EQ(files.size(), 17u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    const std::string session = file.parent_path().filename().string();
    const AnchorSurvey survey = readAnchorSurvey(test::pilotSurvey(session).string());
    FlightReadOptions options;
    options.survey = &survey;
    options.required = {Stream::kTdoa, Stream::kPose, Stream::kAcc, Stream::kGyro};
    ReadReport report;
    const Flight f = readFlightCsv(file.string(), options, &report);
    EXPECT_TRUE(f.pose_has_orientation);
    EXPECT_EQ(f.columns, utilTdoaColumns());
    // acc ≈ 1 g at the start (on the ground)
    EXPECT_NEAR(f.acc.front().b_value.norm(), kGravity_mps2, 0.5);
    const Flight again = parseFlightCsv(formatFlightCsv(f), file.string());
    EXPECT_TRUE(test::flightsIdentical(f, again));
  }
}

TEST(RealDataUtilCsv, EveryFinalExtractFlightReadsAsPositionOnly) {
  const auto dir = test::realDir() / "util-final-extract";
  const auto files = csvFilesUnder(dir);
  if (files.empty()) GTEST_SKIP() << "util-final-extract not found under " << dir;
  ASSERT_EQ(files.size(), 6u);
  const AnchorSurvey survey = readAnchorSurvey((dir / "survey" / "anchor_const4_survey.txt").string());
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    FlightReadOptions options;
    options.survey = &survey;
    options.required = {Stream::kTdoa, Stream::kPose};
    const Flight f = readFlightCsv(file.string(), options);
    EXPECT_FALSE(f.pose_has_orientation);
    EXPECT_GT(f.tdoa.size(), 58000u);
    EXPECT_GT(f.pose.size(), 25000u);
    EXPECT_LT(f.pose.size(), f.tdoa.size());
    const Flight again = parseFlightCsv(formatFlightCsv(f), file.string());
    EXPECT_TRUE(test::flightsIdentical(f, again));
  }
}

}  // namespace
}  // namespace uwb
