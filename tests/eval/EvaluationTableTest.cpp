/** @file EvaluationTableTest.cpp */
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "uwb/eval/EvaluationTable.h"

namespace uwb {

TEST(EvaluationTable, AggregatesMeansOverFlightsAndSpreadOverRepeats) {
  // GIVEN two repeats of one configuration on two flights
  const auto run = [](std::string kernel, int inducing, int repeat, std::string flight, double unc, double cor,
                      double seconds) {
    EvaluationRun r;
    r.kernel = std::move(kernel);
    r.inducing = inducing;
    r.repeat = repeat;
    r.flight = std::move(flight);
    r.rmse_uncorrected_m = unc;
    r.rmse_corrected_m = cor;
    r.train_seconds = seconds;
    return r;
  };
  std::vector<EvaluationRun> runs = {
      run("tdoa", 30, 0, "a", 0.20, 0.18, 1.0), run("tdoa", 30, 0, "b", 0.30, 0.24, 1.0),
      run("tdoa", 30, 1, "a", 0.20, 0.16, 3.0), run("tdoa", 30, 1, "b", 0.30, 0.30, 3.0),
      run("z1", 10, 0, "a", 0.20, 0.25, 1.0),
  };
  // WHEN we aggregate
  const auto rows = aggregateRuns(runs);
  // THEN the row means are over repeats and flights, min/max are per-repeat changes (negative = error reduced)
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].kernel, "tdoa");
  EXPECT_EQ(rows[0].n_repeats, 2);
  EXPECT_EQ(rows[0].n_flights, 2);
  EXPECT_NEAR(rows[0].rmse_uncorrected_m, 0.25, 1e-12);
  EXPECT_NEAR(rows[0].rmse_corrected_m, 0.22, 1e-12);
  EXPECT_NEAR(rows[0].change_pct, -12.0, 1e-9);
  EXPECT_NEAR(rows[0].change_pct_min, 100.0 * (0.21 / 0.25 - 1), 1e-9);  // repeat 0, the better one
  EXPECT_NEAR(rows[0].change_pct_max, 100.0 * (0.23 / 0.25 - 1), 1e-9);  // repeat 1
  EXPECT_NEAR(rows[0].train_seconds, 2.0, 1e-12);
  EXPECT_NEAR(rows[1].change_pct, 25.0, 1e-9);  // a correction can make things worse: positive
  // AND the JSON carries the keys of the results.json contract
  const auto j = toJson(rows);
  for (const char* key : {"kernel", "inducing", "rmse_uncorrected_m", "rmse_corrected_m", "change_pct",
                          "change_pct_min", "change_pct_max", "coverage_1sigma", "coverage_2sigma", "nlpd"}) {
    EXPECT_TRUE(j[0].contains(key)) << key;
  }
  EXPECT_NE(toMarkdown(rows).find("| tdoa | 30 |"), std::string::npos);
  EXPECT_NE(toMarkdown(rows).find("| -12.0 |"), std::string::npos);
  // AND the per-run JSON and the per-flight table say the same with the same sign
  EXPECT_NEAR(runsToJson(runs)[0].at("change_pct").get<double>(), -10.0, 1e-9);
  EXPECT_NE(perFlightMarkdown(runs, "tdoa", 30).find("| b | 0.300 | 0.270 | -10.0 |"), std::string::npos);
}

}  // namespace uwb
