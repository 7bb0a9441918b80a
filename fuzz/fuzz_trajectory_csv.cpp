/** @file fuzz_trajectory_csv.cpp
 *  @brief libFuzzer harness of the estimated-trajectory CSV reader (uwb::parseTrajectoryCsv).
 */
#include "FuzzInput.h"
#include "uwb/io/TrajectoryCsv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  uwb::fuzz::expectCleanRejection([&] { (void)uwb::parseTrajectoryCsv(uwb::fuzz::asText(data, size), "fuzz-traj.csv"); });
  return 0;
}
