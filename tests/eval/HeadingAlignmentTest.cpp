/** @file HeadingAlignmentTest.cpp
 *  @brief The heading alignment (docs/math/filter.md F28) on a simulated yawing figure eight logged from mid-air:
 *         off (the default) the heading stays at the assumed 0 and is off by the true heading; on, it is found.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "uwb/eval/Localization.h"
#include "uwb/eval/ProtocolScenarios.h"
#include "uwb/filter/InMotionAlignment.h"

namespace uwb {
namespace {

/// Mean |heading error| of the estimate against the simulated pose over [t_from, ∞) [rad].
double meanHeadingError(const LocalizationRun& run, const Flight& truth, double t_from) {
  double sum = 0.0;
  int n = 0;
  for (const TrajectorySample& s : run.trajectory) {
    if (s.t_s < t_from) continue;
    const auto it = std::lower_bound(truth.pose.begin(), truth.pose.end(), s.t_s,
                                     [](const PoseSample& p, double t) { return p.t_s < t; });
    if (it == truth.pose.end()) break;
    sum += std::abs(wrapAngle(headingOf(s.w_q_b) - headingOf(it->w_q_b)));
    ++n;
  }
  return n > 0 ? sum / n : NAN;
}

TEST(HeadingAlignment, AYawingStartInTheAirFindsItsHeading) {
  // GIVEN a yawing figure eight logged from 6 s after its climb (true heading at the log's start ≈ 130°)
  const std::vector<SimScenarioRun> runs = protocolSimulations("", {11}, "yawing-start-paper-s11");
  ASSERT_EQ(runs.size(), 1u);
  const SimScenarioRun& sc = runs.front();
  const double t_from = sc.flight.timeSpan().first + 15.0;
  LocalizationOptions off;
  off.params.heading_alignment = false;
  const LocalizationRun base = localizeFlight(sc.flight, sc.survey, off);
  LocalizationOptions on;
  on.params.heading_alignment = true;
  // WHEN the filter runs with the heading alignment on (the default)
  const LocalizationRun aligned = localizeFlight(sc.flight, sc.survey, on);
  // THEN without it the heading stays wrong; with it, it is found within 20° after 15 s, and the position holds
  EXPECT_EQ(base.summary.n_heading_alignments, 0u);
  EXPECT_GT(meanHeadingError(base, sc.flight, t_from), 1.5);
  EXPECT_GE(aligned.summary.n_heading_alignments, 1u);
  EXPECT_EQ(aligned.summary.heading_alignment_t_s.size(), aligned.summary.n_heading_alignments);
  EXPECT_LT(meanHeadingError(aligned, sc.flight, t_from), 20.0 * M_PI / 180.0);
  ASSERT_TRUE(base.metrics && aligned.metrics);
  EXPECT_LT(aligned.metrics->airborne.rmse_m, 1.05 * base.metrics->airborne.rmse_m);
}

}  // namespace
}  // namespace uwb
