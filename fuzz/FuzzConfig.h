/** @file FuzzConfig.h
 *  @brief Shared by the config harnesses: a config file's text → JSON parse, then the `localize` config reader
 *         (EkfParams, then validate()) on the parsed document, each allowed to reject the input cleanly.
 */
#pragma once

#include <string>
#include <string_view>

#include "EkfConfig.h"
#include "FuzzInput.h"
#include "uwb/io/JsonFile.h"

namespace uwb::fuzz {

/// Parses `text` as the config file `source`, reads it as `localize --config` would, then runs `more(j)` on the
/// parsed document (a failed parse ends it there).
template <class F>
void readConfigText(std::string_view text, const std::string& source, F&& more) {
  expectCleanRejection([&] {
    const nlohmann::json j = parseJsonText(text, source, "config file");
    expectCleanRejection([&] {
      EkfParams params;
      app::applyEkfConfig(j, source, params);
      params.validate();
    });
    more(j);
  });
}

}  // namespace uwb::fuzz
