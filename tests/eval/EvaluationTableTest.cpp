/** @file EvaluationTableTest.cpp */
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "uwb/eval/EvaluationTable.h"

namespace uwb {

TEST(EvaluationTable, AggregatesMeansOverFlightsAndSpreadOverRepeats) {
  // GIVEN two repeats of one configuration on two flights
  std::vector<EvaluationRun> runs = {
      {"tdoa", 30, 0, "a", 0.20, 0.18, 0, 0, 1.0}, {"tdoa", 30, 0, "b", 0.30, 0.24, 0, 0, 1.0},
      {"tdoa", 30, 1, "a", 0.20, 0.16, 0, 0, 3.0}, {"tdoa", 30, 1, "b", 0.30, 0.30, 0, 0, 3.0},
      {"z1", 10, 0, "a", 0.20, 0.25, 0, 0, 1.0},
  };
  // WHEN we aggregate
  const auto rows = aggregateRuns(runs);
  // THEN the row means are over repeats and flights, min/max are per-repeat improvements
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].kernel, "tdoa");
  EXPECT_EQ(rows[0].n_repeats, 2);
  EXPECT_EQ(rows[0].n_flights, 2);
  EXPECT_NEAR(rows[0].rmse_uncorrected_m, 0.25, 1e-12);
  EXPECT_NEAR(rows[0].rmse_corrected_m, 0.22, 1e-12);
  EXPECT_NEAR(rows[0].improvement_pct, 12.0, 1e-9);
  EXPECT_NEAR(rows[0].improvement_pct_min, 100.0 * (1 - 0.23 / 0.25), 1e-9);  // repeat 1
  EXPECT_NEAR(rows[0].improvement_pct_max, 100.0 * (1 - 0.21 / 0.25), 1e-9);  // repeat 0
  EXPECT_NEAR(rows[0].train_seconds, 2.0, 1e-12);
  EXPECT_NEAR(rows[1].improvement_pct, -25.0, 1e-9);  // a correction can make things worse
  // AND the JSON carries the keys of the results.json contract
  const auto j = toJson(rows);
  for (const char* key : {"kernel", "inducing", "rmse_uncorrected_m", "rmse_corrected_m", "improvement_pct",
                          "improvement_pct_min", "improvement_pct_max"}) {
    EXPECT_TRUE(j[0].contains(key)) << key;
  }
  EXPECT_NE(toMarkdown(rows).find("| tdoa | 30 |"), std::string::npos);
}

}  // namespace uwb
