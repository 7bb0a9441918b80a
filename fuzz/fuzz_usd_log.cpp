/** @file fuzz_usd_log.cpp
 *  @brief libFuzzer harness of the uSD-card event-log reader (uwb::parseUsdLog), strict and in salvage mode,
 *         followed by what `uwbtdoa import` does with an accepted log (the import into a flight, the flight CSV
 *         round trip that must reproduce it, and the log writer whose output must read back to the same bytes).
 */
#include "FuzzInput.h"
#include "uwb/io/UsdImport.h"
#include "uwb/io/UsdLog.h"
#include "uwb/io/UtilCsv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  const std::string_view bytes = fuzz::asText(data, size);
  for (const bool salvage : {false, true}) {
    fuzz::expectCleanRejection([&] {
      UsdReadOptions options;
      options.salvage = salvage;
      UsdReadReport report;
      const UsdLog log = parseUsdLog(bytes, "fuzz.log", options, &report);
      const std::string written = formatUsdLog(log);
      if (formatUsdLog(parseUsdLog(written, "fuzz-rewritten.log")) != written) {
        __builtin_trap();  // the writer and the reader disagree
      }
      const Flight flight = flightFromUsdLog(log);
      Flight again;
      try {
        again = parseFlightCsv(formatFlightCsv(flight), "fuzz-import.csv");
      } catch (const std::exception&) {
        __builtin_trap();  // the import accepted what the flight CSV refuses
      }
      if (again.tdoa.size() != flight.tdoa.size() || again.pose.size() != flight.pose.size() ||
          again.acc.size() != flight.acc.size() || again.twr.size() != flight.twr.size()) {
        __builtin_trap();  // the imported flight does not survive its CSV
      }
    });
  }
  return 0;
}
