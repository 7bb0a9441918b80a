/** @file EstimateStreamTest.cpp
 *  @brief The online loop gives the batch path's estimates (same events, same order, same output period), and an
 *         estimate survives its text form (JSON lines and CSV) bit for bit.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "uwb/core/Error.h"
#include "uwb/eval/Localization.h"
#include "uwb/filter/TdoaLocalizer.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/stream/EstimateFormat.h"
#include "uwb/stream/EstimateStream.h"
#include "uwb/stream/LineProtocol.h"

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
std::vector<LocalizerEstimate> streamThroughText(const SimulatedCase& c, const EkfParams& p, double period_s,
                                                const BiasPredictor& bias = {}) {
  EstimateStream stream(p, c.anchors, period_s, bias);
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

TEST(EstimateStream, WithTheBiasGuardGivesTheBatchEstimates) {
  // GIVEN a simulated flight, a bias model that shifts every TDoA of anchor 1 (wrong for this flight), and the bias
  // guard (F24), which runs the corrected and the uncorrected filter side by side
  const SimulatedCase& c = simulatedCase();
  const BiasPredictor bias = [](const TdoaFeature& f) { return BiasPrediction{f.id_a == 1 ? 0.3 : 0.0, 0.0, 1.0}; };
  EkfParams p;
  p.bias_guard = true;
  // WHEN the batch path runs, and the same events go through the stream one at a time
  const LocalizerResult batch = TdoaLocalizer(p, c.anchors, bias).run(c.log, 0.01);
  const std::vector<LocalizerEstimate> online = streamThroughText(c, p, 0.01, bias);
  // THEN the guard is in use (a weight is reported) and the stream gives the batch estimates exactly
  EXPECT_FALSE(std::isnan(batch.summary.bias_guard_final_weight));
  ASSERT_GT(batch.estimates.size(), 100u);
  ASSERT_EQ(online.size(), batch.estimates.size());
  for (std::size_t i = 0; i < online.size(); ++i) {
    ASSERT_EQ(online[i].t_s, batch.estimates[i].t_s) << i;
    ASSERT_EQ(online[i].x.w_p_b, batch.estimates[i].x.w_p_b) << i;
    ASSERT_EQ(online[i].cov_pose, batch.estimates[i].cov_pose) << i;
  }
  // AND the guarded output differs from the corrected filter alone (the mixture is not a no-op here)
  EkfParams off = p;
  off.bias_guard = false;
  const LocalizerResult unguarded = TdoaLocalizer(off, c.anchors, bias).run(c.log, 0.01);
  ASSERT_EQ(unguarded.estimates.size(), batch.estimates.size());
  EXPECT_NE(unguarded.estimates.back().x.w_p_b, batch.estimates.back().x.w_p_b);
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
  // AND a TUM line (t x y z qx qy qz qw, for evo) gives back the same time and pose
  const std::string tum = formatEstimate(e, EstimateFormat::kTum);
  EXPECT_EQ(std::count(tum.begin(), tum.end(), ' '), 7);
  const LocalizerEstimate pose = parseEstimate(tum, EstimateFormat::kTum);
  EXPECT_EQ(pose.t_s, e.t_s);
  EXPECT_EQ(pose.x.w_p_b, e.x.w_p_b);
  EXPECT_EQ(pose.x.w_q_b.coeffs(), e.x.w_q_b.coeffs());
  EXPECT_EQ(estimateHeader(EstimateFormat::kTum), "# timestamp tx ty tz qx qy qz qw");
  EXPECT_THROW((void)parseEstimate("1 2 3", EstimateFormat::kTum), InputError);
  // AND the CSV header has as many columns as a row
  const std::string row = formatEstimate(e, EstimateFormat::kCsv);
  const std::string header = estimateCsvHeader();
  EXPECT_EQ(std::count(row.begin(), row.end(), ','), std::count(header.begin(), header.end(), ','));
}

}  // namespace
}  // namespace uwb
