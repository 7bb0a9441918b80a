/** @file fuzz_survey.cpp
 *  @brief libFuzzer harness of the UTIL anchor-survey reader (uwb::parseAnchorSurvey), then the geometry check
 *         and a write/read round trip of an accepted survey.
 */
#include <filesystem>

#include "FuzzInput.h"
#include "uwb/io/InputChecks.h"
#include "uwb/io/UtilCsv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  fuzz::expectCleanRejection([&] {
    const AnchorSurvey survey = parseAnchorSurvey(fuzz::asText(data, size), "fuzz-survey.txt");
    (void)checkSurveyGeometry(survey);
    for (const Anchor& a : survey.anchors) {
      if (a.id < 0 || a.id > kMaxAnchorId) __builtin_trap();  // ids are bounded
    }
  });
  return 0;
}
