/** @file cmd_params.cpp
 *  @brief `uwbtdoa params [--markdown | --json]`: every filter parameter (EkfParams) with its unit, default, valid
 *         range and description, from the parameter registry; `--markdown` prints the table of docs/parameters.md.
 */
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "Command.h"
#include "uwb/filter/EkfParamRegistry.h"

namespace {

struct ParamsArgs {
  bool markdown = false, json_out = false;
};

void runParams(const ParamsArgs& a) {
  if (a.markdown) {
    std::cout << uwb::ekfParamMarkdownTable();
    return;
  }
  const uwb::EkfParams defaults;
  if (a.json_out) {
    nlohmann::json j = nlohmann::json::array();
    for (const uwb::EkfParamInfo& i : uwb::ekfParamRegistry()) {
      j.push_back({{"name", i.name},
                   {"flag", i.flag()},
                   {"unit", i.unit},
                   {"default", uwb::ekfParamText(defaults, i)},
                   {"help", uwb::ekfParamHelpSuffix(i)},
                   {"doc", i.doc}});
    }
    std::cout << j.dump() << '\n';
    return;
  }
  for (const uwb::EkfParamInfo& i : uwb::ekfParamRegistry()) {
    std::cout << i.name << " " << uwb::ekfParamHelpSuffix(i) << "\n    " << i.doc << "\n";
  }
}

const bool kRegistered = uwb::app::registerCommand(
    {"params", "List the filter parameters (config keys, localize flags, units, defaults, ranges)",
     [](CLI::App& sub) {
       auto a = std::make_shared<ParamsArgs>();
       sub.add_flag("--markdown", a->markdown, "Print the Markdown table of docs/parameters.md");
       sub.add_flag("--json", a->json_out, "Print one JSON array");
       sub.callback([a] { runParams(*a); });
     }});

}  // namespace
