/** @file cmd_paths.cpp
 *  @brief `uwbtdoa paths`: prints where the tool looks for real data (handy when a test skips).
 */
#include <iostream>

#include "Command.h"

namespace {
const bool kRegistered = uwb::app::registerCommand(
    {"paths", "Print the data directory the tools use ($UWBTDOA_DATA or ../shared/data)",
     [](CLI::App& sub) { sub.callback([] { std::cout << uwb::app::defaultDataDir() << '\n'; }); }});
}  // namespace
