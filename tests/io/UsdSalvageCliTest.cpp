/** @file UsdSalvageCliTest.cpp
 *  @brief `uwbtdoa import --salvage` on logs damaged in the middle (docs/robustness.md): the reader resynchronises
 *         on the next valid event and keeps what follows, counting what it skipped; a zeroed block, whose events
 *         decode as stamped 0, is dropped with a warning instead of moving the flight's time zero. The damaged logs
 *         are crafted from a valid one, the uSD-card event log of a short simulated flight, with event ids from 0
 *         (as the deck numbers them), so that zeros decode as events.
 */
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/IoTestHelpers.h"
#include "support/TestSupport.h"
#include "uwb/io/UsdImport.h"
#include "uwb/io/UsdLog.h"
#include "uwb/io/UtilCsv.h"

namespace uwb {
namespace {

using ::testing::HasSubstr;

/// `log` with its event types numbered 0, 1, 2, … in header order (usdLogFromFlight numbers them from 1, leaving gaps
/// for absent streams), events in file order: zeros then decode as events of the first type.
UsdLog idsFromZero(const UsdLog& log) {
  UsdLog out;
  out.version = log.version;
  for (std::size_t i = 0; i < log.types.size(); ++i) {
    std::vector<std::pair<std::string, UsdType>> fields;
    for (const UsdField& f : log.types[i].fields) fields.emplace_back(f.name, f.type);
    out.addType(static_cast<std::uint16_t>(i), log.types[i].name, fields);
  }
  struct Ref {
    std::uint32_t number;
    std::size_t type, event;
  };
  std::vector<Ref> order;
  for (std::size_t k = 0; k < log.events.size(); ++k)
    for (std::size_t e = 0; e < log.events[k].size(); ++e) order.push_back({log.events[k].number[e], k, e});
  std::sort(order.begin(), order.end(), [](const Ref& a, const Ref& b) { return a.number < b.number; });
  for (const Ref& r : order) {
    std::vector<double> values;
    for (std::size_t f = 0; f < log.types[r.type].fields.size(); ++f) values.push_back(log.value(r.type, r.event, f));
    out.addEvent(r.type, log.events[r.type].t_us[r.event], values);
  }
  return out;
}

class SalvageCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(test::cliPath())) return;
    dir_ = new test::TempDir;
    const std::string csv = dir_->file("sim.csv");
    const test::CliResult sim =
        test::runCli("simulate --trajectory circle --duration 20 --seed 4 --out " + csv + " --survey-out " +
                     dir_->file("survey.txt"));
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
    flight_ = new Flight(readFlightCsv(csv));
    bytes_ = new std::string(formatUsdLog(idsFromZero(usdLogFromFlight(*flight_))));
  }
  static void TearDownTestSuite() {
    delete bytes_;
    delete flight_;
    delete dir_;
  }
  void SetUp() override {
    UWB_REQUIRE_CLI();
  }
  /// Header bytes (the events start after them): a log with the types and no event, less its CRC.
  static std::size_t headerBytes() {
    UsdLog empty;
    for (const UsdEventType& t : usdLogFromFlight(*flight_).types) {
      std::vector<std::pair<std::string, UsdType>> fields;
      for (const UsdField& f : t.fields) fields.emplace_back(f.name, f.type);
      empty.addType(t.id, t.name, fields);
    }
    return formatUsdLog(empty).size() - 4;
  }
  static test::TempDir* dir_;
  static Flight* flight_;
  static std::string* bytes_;
};
test::TempDir* SalvageCli::dir_ = nullptr;
Flight* SalvageCli::flight_ = nullptr;
std::string* SalvageCli::bytes_ = nullptr;

TEST_F(SalvageCli, ADamagedBlockInTheMiddleLosesOnlyItsOwnEvents) {
  // GIVEN 20 copies of the log, each with 300 pseudo-random bytes written at another place of the events
  const std::size_t header = headerBytes(), events = bytes_->size() - header - 4;
  std::uint64_t rng = 12345;
  int n_ok = 0;
  for (int k = 0; k < 20; ++k) {
    std::string bytes = *bytes_;
    const std::size_t at = header + events / 10 + static_cast<std::size_t>(k) * (events * 8 / 10) / 20 + 7 * k;
    for (std::size_t i = 0; i < 300; ++i) {
      rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
      bytes[at + i] = static_cast<char>(rng >> 56);
    }
    const std::string in = dir_->write("damaged" + std::to_string(k) + ".log", bytes);
    const std::string out = dir_->file("damaged" + std::to_string(k) + ".csv");
    // WHEN it is imported with --salvage
    const test::CliResult r = test::runCli("import " + in + " --salvage --json --out " + out);
    // THEN a flight comes out with nearly every event (300 bytes hold about 15 events), the skipped bytes are
    // counted and the warning says so
    ASSERT_EQ(r.exit_code, 0) << "block at byte " << at << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_GT(j.at("skipped_bytes").get<std::size_t>(), 0u) << at;
    EXPECT_LE(j.at("skipped_bytes").get<std::size_t>(), 400u) << at;
    EXPECT_THAT(j.at("warnings").dump(), HasSubstr("damaged byte(s) skipped")) << at;
    const Flight f = readFlightCsv(out);
    EXPECT_GE(f.tdoa.size() + 10, flight_->tdoa.size()) << at;
    EXPECT_GE(f.acc.size() + 20, flight_->acc.size()) << at;
    EXPECT_NEAR(f.tdoa.back().t_s, flight_->tdoa.back().t_s, 1e-6) << at;
    EXPECT_NEAR(f.tdoa.front().t_s, flight_->tdoa.front().t_s, 1e-6) << at;
    n_ok += r.exit_code == 0;
  }
  EXPECT_EQ(n_ok, 20);
}

TEST_F(SalvageCli, AZeroedBlockIsDroppedWithAWarningNeverShiftingTheFlight) {
  // GIVEN the log with 8 KiB of zeros at 40 % of its events (events of id 0 stamped 0)
  const std::size_t header = headerBytes(), events = bytes_->size() - header - 4;
  std::string bytes = *bytes_;
  std::fill_n(bytes.begin() + static_cast<std::ptrdiff_t>(header + events * 4 / 10), 8192, '\0');
  const std::string in = dir_->write("zeroed.log", bytes), out = dir_->file("zeroed.csv");
  // WHEN it is imported with --salvage
  const test::CliResult r = test::runCli("import " + in + " --salvage --json --out " + out);
  // THEN the zero-stamped events are dropped and counted with a warning; the flight keeps its time zero and its span
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j.at("dropped_events").get<std::size_t>(), 100u) << r.out;
  EXPECT_THAT(j.at("warnings").dump(), HasSubstr("time stamps jump off the log's clock"));
  const Flight f = readFlightCsv(out);
  EXPECT_NEAR(f.tdoa.front().t_s, flight_->tdoa.front().t_s, 1e-6);
  EXPECT_NEAR(f.acc.front().t_s, flight_->acc.front().t_s, 1e-6);
  EXPECT_NEAR(f.tdoa.back().t_s, flight_->tdoa.back().t_s, 1e-6);
  for (const auto& z : f.tdoa) ASSERT_NE(z.id_a, z.id_b) << z.t_s;  // no zero-payload TDoA (ids 0, 0) kept
  // AND without --salvage the damaged log is still an error that writes nothing
  const test::CliResult strict = test::runCli("import " + in + " --out " + dir_->file("strict.csv"));
  EXPECT_EQ(strict.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir_->file("strict.csv")));
}

}  // namespace
}  // namespace uwb
