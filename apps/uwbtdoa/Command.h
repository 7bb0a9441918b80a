/** @file Command.h
 *  @brief Subcommand registry of the `uwbtdoa` CLI. Each cmd_<name>.cpp registers itself at static-init time:
 *
 *    static const bool kRegistered = uwb::app::registerCommand({"inspect", "Summarize a flight", setup});
 *
 *  `setup` adds options to the CLI11 subcommand and sets its callback. Callbacks throw on error; main()
 *  prints the message on stderr and exits non-zero. With `--json`, a command prints exactly one JSON object.
 */
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace uwb::app {

struct CommandSpec {
  std::string name;
  std::string description;
  std::function<void(CLI::App& sub)> setup;
};

bool registerCommand(CommandSpec spec);
std::vector<CommandSpec>& commandRegistry();

/// The command line the tool was started with, shell-quoted where needed (for reports).
const std::string& commandLine();
void setCommandLine(int argc, char** argv);

/// Default real-data directory: $UWBTDOA_DATA, else the build-time default (../shared/data).
std::string defaultDataDir();

}  // namespace uwb::app
