/** @file fuzz_json_deep.cpp
 *  @brief libFuzzer harness of the JSON reader on deep and wide documents (run with -max_len=300000, which reaches
 *         nesting of 100 000 levels and arrays of 100 000 members; the other harnesses stop at 64 KiB): the text →
 *         JSON parse (parseJsonText, its errors with their location), then the `localize` config reader, whose
 *         errors print the offending value, and the typed accessors on the top level.
 */
#include "FuzzConfig.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uwb;
  fuzz::readConfigText(fuzz::asText(data, size), "fuzz-deep.json", [](const nlohmann::json& j) {
    if (j.is_object())
      for (const auto& item : j.items()) {
        const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture one
        const auto& value = item.value();
        fuzz::expectCleanRejection([&] { (void)jsonDouble(value, key); });
        fuzz::expectCleanRejection([&] { (void)jsonString(value, key); });
      }
  });
  return 0;
}
