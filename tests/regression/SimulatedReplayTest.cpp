/** @file SimulatedReplayTest.cpp
 *  @brief A short committed replay (STYLE §1, tests/regression): a 24 s simulated circle flight (the simulator with
 *         a fixed seed, the paper's eight anchors) localized with the default filter, compared with the committed
 *         reference output tests/regression/data/sim_circle_seed7.csv (trajectory every 0.2 s and the summary).
 *
 *  Any change of the filter's numbers shows here, with or without the real data. A deliberate change regenerates
 *  the reference: UWB_REGENERATE_REFERENCE=1 build/tests/test_regression --gtest_filter='SimulatedReplay.*'
 *  (then review and commit the new file).
 */
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "uwb/eval/Localization.h"
#include "uwb/sim/FlightSimulator.h"
#include "uwb/sim/Scenario.h"

namespace uwb {
namespace {

constexpr std::uint64_t kSeed = 7;
constexpr double kDuration_s = 24.0;  // the shortest circle flight the simulator makes is 20 s
constexpr double kRowPeriod_s = 0.2;  ///< one reference row per 20 trajectory samples (output period 0.01 s)

struct Replay {
  std::string header;             ///< "# airborne_rmse_m=…,n_tdoa_used=…,n_tdoa_rejected=…"
  std::vector<std::vector<double>> rows;  ///< t_s, x_m, y_m, z_m
};

Replay replay() {
  const sim::SimResult sim = sim::simulateFlight(
      sim::makeScenario(sim::paperAnchors(), sim::TrajectoryShape::kCircle, kDuration_s), sim::SimParams{}, kSeed);
  const LocalizationRun run = localizeFlight(sim.flight, sim.survey);
  Replay r;
  r.header = fmt::format("# airborne_rmse_m={:.17g},n_tdoa_used={},n_tdoa_rejected={}",
                         run.metrics ? run.metrics->airborne.rmse_m : -1.0, run.summary.n_tdoa_used,
                         run.summary.n_tdoa_rejected);
  const std::size_t stride = static_cast<std::size_t>(std::lround(kRowPeriod_s / 0.01));
  for (std::size_t i = 0; i < run.trajectory.size(); i += stride) {
    const TrajectorySample& s = run.trajectory[i];
    r.rows.push_back({s.t_s, s.w_p_b.x(), s.w_p_b.y(), s.w_p_b.z()});
  }
  return r;
}

std::string referencePath() { return std::string(UWB_REGRESSION_DATA_DIR) + "/sim_circle_seed7.csv"; }

void write(const Replay& r, const std::string& path) {
  std::ofstream out(path);
  out << r.header << "\nt_s,x_m,y_m,z_m\n";
  for (const auto& row : r.rows) out << fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}\n", row[0], row[1], row[2], row[3]);
}

Replay read(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open the reference " + path);
  Replay r;
  std::string line;
  std::getline(in, r.header);
  std::getline(in, line);  // column names
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    r.rows.push_back(row);
  }
  return r;
}

TEST(SimulatedReplay, DefaultFilterReproducesTheCommittedReference) {
  // GIVEN the simulated flight and the committed reference output
  // WHEN the flight is localized again
  const Replay now = replay();
  if (std::getenv("UWB_REGENERATE_REFERENCE") != nullptr) {
    write(now, referencePath());
    GTEST_SKIP() << "reference written to " << referencePath();
  }
  const Replay ref = read(referencePath());
  // THEN the summary is the same and every position agrees to 1 µm (the last bits may differ between compilers
  // and instruction sets; a change of the filter moves them by millimetres or more)
  const auto rmse = [](const std::string& header) { return std::stod(header.substr(header.find('=') + 1)); };
  const auto counts = [](const std::string& header) { return header.substr(header.find(',')); };
  EXPECT_NEAR(rmse(now.header), rmse(ref.header), 1e-9) << now.header << "\nreference\n" << ref.header;
  EXPECT_EQ(counts(now.header), counts(ref.header));
  EXPECT_GT(rmse(ref.header), 0.0);
  ASSERT_EQ(now.rows.size(), ref.rows.size());
  ASSERT_GT(now.rows.size(), 100u);
  double worst = 0.0;
  std::size_t worst_row = 0;
  for (std::size_t i = 0; i < now.rows.size(); ++i) {
    ASSERT_EQ(ref.rows[i].size(), 4u) << "reference row " << i + 3;
    EXPECT_NEAR(now.rows[i][0], ref.rows[i][0], 1e-9) << "time of row " << i;
    for (int k = 1; k < 4; ++k) {
      const double d = std::abs(now.rows[i][k] - ref.rows[i][k]);
      if (!(d <= worst)) worst = d, worst_row = i;
    }
  }
  EXPECT_LT(worst, 1e-6) << "largest position difference at t = " << now.rows[worst_row][0] << " s";
}

}  // namespace
}  // namespace uwb
