#pragma once
// Registry of `epichead` subcommands. A command file defines one static CommandRegistration:
//
//   static const CommandRegistration reg{"score", "Score poses against ground truth",
//       [](CLI::App& app) { ...add options...; return [=]() -> int { ...run...; }; }};
//
// The setup function adds the command's options to its CLI11 subcommand and returns the
// action to run once the command line has parsed. Actions return the process exit code.
#include <functional>
#include <string>
#include <vector>

namespace CLI { class App; }

namespace epichead::tools {

using CommandAction = std::function<int()>;
using CommandSetup = std::function<CommandAction(CLI::App&)>;

struct Command {
  std::string name;
  std::string summary;
  CommandSetup setup;
};

// All registered commands, in registration order.
std::vector<Command>& command_registry();

struct CommandRegistration {
  CommandRegistration(std::string name, std::string summary, CommandSetup setup);
};

// Exit codes: 0 done, 1 a runtime error (bad input file, device, ...), 2 a command line that
// does not parse (with the usage line on stderr).
inline constexpr int kRuntimeErrorExit = 1;
inline constexpr int kUsageExit = 2;

// Prints "epichead <command>: <reason>" on stderr (escaped: printable.h) and returns
// kRuntimeErrorExit.
int fail(const std::string& command, const std::string& reason);

}  // namespace epichead::tools
