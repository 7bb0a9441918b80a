/** @file EstimateStreamTest.cpp
 *  @brief The online loop gives the batch path's estimates (same events, same order, same output period), and an
 *         estimate survives its text form (JSON lines and CSV) bit for bit.
 */
#include <gtest/gtest.h>

#include "uwb/eval/Localization.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/stream/EstimateFormat.h"
#include "uwb/stream/EstimateStream.h"
#include "uwb/stream/LineProtocol.h"
#include "uwb/stream/ReplayLog.h"

namespace uwb {
namespace {

struct SimulatedCase {
  SensorLog log;
  AnchorTable anchors;
};

/// A simulated 22 s flight (ground, take-off, circle, landing: the simulator's shortest), made once.
const SimulatedCase& simulatedCase() {
  static const SimulatedCase c = [] {
    const sim::SimResult r = sim::simulateFlight(
        sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kCircle, 22.0), sim::SimParams{}, 5);
    return SimulatedCase{replayLogFromFlight(r.flight), anchorTableFromSurvey(r.survey, EkfParams{}.anchor_sigma_m)};
  }();
  return c;
}

/// The log's events through their text lines into an EstimateStream.
std::vector<LocalizerEstimate> streamThroughText(const SimulatedCase& c, const EkfParams& p, double period_s) {
  EstimateStream stream(p, c.anchors, period_s);
  std::vector<LocalizerEstimate> out;
  SensorEventCursor cursor(c.log);
  std::size_t line_no = 0;
  for (SensorEvent ev; cursor.next(ev);)
    if (stream.add(parseEventLine(formatEventLine(c.log, ev), ++line_no))) out.push_back(stream.last());
  if (stream.finish()) out.push_back(stream.last());
  return out;
}

TEST(EstimateStream, TextEventsGiveTheBatchEstimatesForEveryOutputPeriod) {
  // GIVEN a simulated flight with all phases
  const SimulatedCase& c = simulatedCase();
  const EkfParams p;
  for (double period_s : {0.0, 0.01, 0.137}) {
    // WHEN the batch path runs, and the same events go through the line protocol one at a time
    const LocalizerResult batch = TdoaLocalizer(p, c.anchors).run(c.log, period_s);
    const std::vector<LocalizerEstimate> online = streamThroughText(c, p, period_s);
    // THEN the same number of estimates, at the same stamps, with the same state and covariance
    ASSERT_GT(batch.estimates.size(), 100u) << period_s;
    ASSERT_EQ(online.size(), batch.estimates.size()) << period_s;
    for (std::size_t i = 0; i < online.size(); ++i) {
      const LocalizerEstimate& a = online[i];
      const LocalizerEstimate& b = batch.estimates[i];
      ASSERT_EQ(a.t_s, b.t_s) << i;
      ASSERT_EQ(a.x.w_p_b, b.x.w_p_b) << i;
      ASSERT_EQ(a.x.w_q_b.coeffs(), b.x.w_q_b.coeffs()) << i;
      ASSERT_EQ(a.cov_pose, b.cov_pose) << i;
      ASSERT_EQ(a.phase, b.phase) << i;
    }
  }
}

TEST(EstimateStream, NoEstimateBeforeThePositionIsKnownAndNoneForComments) {
  const SimulatedCase& c = simulatedCase();
  EstimateStream stream(EkfParams{}, c.anchors, 0.01);
  EXPECT_FALSE(stream.add(parseEventLine("# a comment", 1)));
  EXPECT_FALSE(stream.finish());  // nothing in yet
  EXPECT_EQ(stream.eventsIn(), 0u);
  EXPECT_THROW(EstimateStream(EkfParams{}, c.anchors, -1.0), std::invalid_argument);
}

TEST(EstimateStream, BiasGuardIsRefusedRatherThanIgnored) {
  // GIVEN a bias model and the bias guard, which only the batch path runs (F24)
  const SimulatedCase& c = simulatedCase();
  const BiasPredictor bias = [](const TdoaFeature&) { return BiasPrediction{}; };
  EkfParams p;
  p.bias_guard = true;
  // THEN the stream refuses it instead of giving estimates that differ from `localize` with the same flags
  EXPECT_THROW(EstimateStream(p, c.anchors, 0.01, bias), std::invalid_argument);
  // AND without a bias model the flag has nothing to guard and the stream runs
  EXPECT_NO_THROW(EstimateStream(p, c.anchors, 0.01));
}

TEST(EstimateFormat, JsonAndCsvLinesReadBackBitForBit) {
  // GIVEN a real estimate of the simulated flight
  const SimulatedCase& c = simulatedCase();
  const LocalizerResult r = TdoaLocalizer(EkfParams{}, c.anchors).run(c.log, 0.5);
  ASSERT_FALSE(r.estimates.empty());
  const LocalizerEstimate& e = r.estimates.back();
  for (EstimateFormat f : {EstimateFormat::kJson, EstimateFormat::kCsv}) {
    // WHEN written as a line and read back
    const std::string line = formatEstimate(e, f);
    EXPECT_EQ(line.find('\n'), std::string::npos);
    const LocalizerEstimate back = parseEstimate(line, f);
    // THEN every field is the same double
    EXPECT_EQ(back.t_s, e.t_s);
    EXPECT_EQ(back.x.w_p_b, e.x.w_p_b);
    EXPECT_EQ(back.x.w_v_b, e.x.w_v_b);
    EXPECT_EQ(back.x.w_q_b.coeffs(), e.x.w_q_b.coeffs());
    EXPECT_EQ(back.cov_pose, e.cov_pose);
    EXPECT_EQ(back.phase, e.phase);
  }
  // AND the CSV header has as many columns as a row
  const std::string row = formatEstimate(e, EstimateFormat::kCsv);
  const std::string header = estimateCsvHeader();
  EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ','));
}

}  // namespace
}  // namespace uwb
