/** @file main.cpp
 *  @brief Entry point of the `uwbtdoa` command-line tool: collects the registered subcommands and runs one.
 */
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <iostream>

#include "Command.h"
#include "StopSignal.h"
#include "uwb/io/FileAccess.h"
#include "uwb/core/Error.h"

namespace uwb::app {

std::vector<CommandSpec>& commandRegistry() {
  static std::vector<CommandSpec> registry;
  return registry;
}

bool registerCommand(CommandSpec spec) {
  commandRegistry().push_back(std::move(spec));
  return true;
}

namespace {
std::string& commandLineStorage() {
  static std::string line;
  return line;
}
}  // namespace

const std::string& commandLine() { return commandLineStorage(); }

void setCommandLine(int argc, char** argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    if (i == 0) arg = "uwbtdoa";
    const bool plain = !arg.empty() && arg.find_first_of(" \t'\"$;&|<>*?()") == std::string::npos;
    if (!line.empty()) line += ' ';
    line += plain ? arg : "'" + arg + "'";
  }
  commandLineStorage() = line;
}

std::string defaultDataDir() {
  if (const char* env = std::getenv("UWBTDOA_DATA"); env != nullptr && *env != '\0') return env;
  return UWB_DEFAULT_DATA_DIR;
}

}  // namespace uwb::app

int main(int argc, char** argv) {
  uwb::app::setCommandLine(argc, argv);
  uwb::app::installCleanupHandlers();  // Ctrl-C or SIGTERM leave no temporary file beside an output
  uwb::protectInputsFromOverwrite();   // no output replaces a file the run read
  CLI::App app{"uwbtdoa: UWB TDoA localization with Gaussian-process bias correction"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "uwbtdoa 0.1.0");
  auto& registry = uwb::app::commandRegistry();
  std::sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  for (const auto& spec : registry) {
    CLI::App* sub = app.add_subcommand(spec.name, spec.description);
    spec.setup(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const uwb::InputError& e) {
    std::cerr << "uwbtdoa: input error: " << e.what() << '\n';
    return 2;
  } catch (const uwb::FileError& e) {
    std::cerr << "uwbtdoa: file error: " << e.what() << '\n';
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "uwbtdoa: error: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
