#pragma once
/// \file cli.hpp
/// \brief Command table of the `contactrom` executable. Each subcommand lives in
/// its own tools/cmd_<name>.cpp and registers itself with a static
/// CommandRegistrar; main() in contactrom.cpp builds the CLI11 app from the table.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace contactrom::cli {

/// A function that adds one subcommand (options and callback) to the app.
using CommandSetup = std::function<void(CLI::App& app)>;

struct CommandEntry {
  std::string name;
  CommandSetup setup;
};

/// The table, in registration order (sorted by name before use).
std::vector<CommandEntry>& command_table();

/// Registers a subcommand at static-initialisation time.
struct CommandRegistrar {
  CommandRegistrar(std::string name, CommandSetup setup) {
    command_table().push_back({std::move(name), std::move(setup)});
  }
};

}  // namespace contactrom::cli
