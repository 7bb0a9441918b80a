/** @file fuzz_flight_csv.cpp
 *  @brief libFuzzer harness of the UTIL flight-CSV reader (uwb::parseFlightCsv), with and without a survey and
 *         required streams, followed by what the CLI does with an accepted flight (inspect's summary, the
 *         plausibility checks, and a write/read round trip that must reproduce it).
 */
#include "FuzzInput.h"
#include "uwb/eval/FlightSummary.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/UtilCsv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  static const AnchorSurvey survey = [] {
    AnchorSurvey s;
    s.source = "fuzz-survey";
    for (int id = 0; id < 8; ++id) s.anchors.push_back({id, Vec3(id % 2, (id / 2) % 2, id / 4), Quat::Identity()});
    return s;
  }();
  const std::string_view text = fuzz::asText(data, size);
  fuzz::expectCleanRejection([&] {
    ReadReport report;
    const Flight flight = parseFlightCsv(text, "fuzz.csv", {}, &report);
    (void)summarizeFlight(flight, nullptr, &report);
    (void)checkStreamRates(flight);
    const Flight again = parseFlightCsv(formatFlightCsv(flight), "fuzz-roundtrip.csv");
    if (again.tdoa.size() != flight.tdoa.size() || again.pose.size() != flight.pose.size() ||
        again.acc.size() != flight.acc.size()) {
      __builtin_trap();  // the writer lost samples the reader accepted
    }
  });
  fuzz::expectCleanRejection([&] {
    FlightReadOptions options;
    options.survey = &survey;
    options.required = {Stream::kTdoa};
    const Flight flight = parseFlightCsv(text, "fuzz.csv", options);
    (void)summarizeFlight(flight, &survey, nullptr);
  });
  return 0;
}
