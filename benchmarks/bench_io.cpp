/** @file bench_io.cpp
 *  @brief Reader/writer throughput of the UTIL flight CSV on a real flight (docs/io.md, "Throughput").
 *
 *  Reads util-pilot/0425/0425-traj5.csv (6.6 MB, the largest 0425 file) from $UWBTDOA_DATA or the build-time
 *  data dir; every benchmark skips with a message when the data is absent. Reports bytes/s (MB/s).
 */
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "uwb/io/PoseTrack.h"
#include "uwb/io/UtilCsv.h"
#include "uwb/sim/TdoaResiduals.h"

namespace {

std::filesystem::path realDir() {
  if (const char* env = std::getenv("UWBTDOA_DATA"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env) / "real";
  }
  return std::filesystem::path(UWB_DEFAULT_DATA_DIR) / "real";
}

std::string benchFlight() { return (realDir() / "util-pilot" / "0425" / "0425-traj5.csv").string(); }

/// Whether benchFlight() exists; when it does not, `state` skips with a message naming it.
bool benchFlightPresent(benchmark::State& state) {
  if (std::filesystem::exists(benchFlight())) return true;
  state.SkipWithError(("real flight absent: " + benchFlight()).c_str());
  return false;
}

void BM_ReadFlightCsv(benchmark::State& state) {
  const std::string path = benchFlight();
  if (!benchFlightPresent(state)) return;
  std::size_t bytes = 0;
  for (auto _ : state) {
    uwb::ReadReport report;
    uwb::Flight f = uwb::readFlightCsv(path, {}, &report);
    benchmark::DoNotOptimize(f.tdoa.data());
    bytes = report.n_bytes;
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * bytes));
  state.counters["file_MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_ReadFlightCsv)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_ParseFlightCsvInMemory(benchmark::State& state) {
  const std::string path = benchFlight();
  if (!benchFlightPresent(state)) return;
  const std::string text = uwb::formatFlightCsv(uwb::readFlightCsv(path));  // same values, shortest form
  for (auto _ : state) {
    uwb::Flight f = uwb::parseFlightCsv(text, path);
    benchmark::DoNotOptimize(f.tdoa.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * text.size()));
}
BENCHMARK(BM_ParseFlightCsvInMemory)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_FormatFlightCsv(benchmark::State& state) {
  const std::string path = benchFlight();
  if (!benchFlightPresent(state)) return;
  const uwb::Flight f = uwb::readFlightCsv(path);
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::string text = uwb::formatFlightCsv(f);
    bytes = text.size();
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * bytes));
}
BENCHMARK(BM_FormatFlightCsv)->Unit(benchmark::kMillisecond)->MinTime(1.0);

void BM_TdoaResiduals(benchmark::State& state) {
  const std::string path = benchFlight();
  const auto survey_path = realDir() / "util-pilot" / "survey" / "anchor_0425_survey.txt";
  if (!std::filesystem::exists(path) || !std::filesystem::exists(survey_path)) {
    state.SkipWithError("real flight or survey absent");
    return;
  }
  const uwb::Flight f = uwb::readFlightCsv(path);
  const uwb::AnchorSurvey survey = uwb::readAnchorSurvey(survey_path.string());
  for (auto _ : state) {
    const uwb::PoseTrack track(f);
    const auto residuals = uwb::tdoaResiduals(f, survey, track);
    benchmark::DoNotOptimize(residuals.data());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * f.tdoa.size()));
}
BENCHMARK(BM_TdoaResiduals)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
