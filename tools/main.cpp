// `epichead`: the single command-line entry point; dispatches to the registered commands.
#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>

#include "command.h"
#include "printable.h"
#include "epichead/firmware_iface/version.h"

namespace epichead::tools {

std::vector<Command>& command_registry() {
  static std::vector<Command> commands;
  return commands;
}

CommandRegistration::CommandRegistration(std::string name, std::string summary, CommandSetup setup) {
  command_registry().push_back({std::move(name), std::move(summary), std::move(setup)});
}

int fail(const std::string& command, const std::string& reason) {
  // The reason holds file names and text from files: shown escaped (printable.h).
  std::cerr << "epichead " << command << ": " << printable(reason) << "\n";
  return 1;
}

}  // namespace epichead::tools

int main(int argc, char** argv) {
  using namespace epichead::tools;
  CLI::App app{"epichead: model-based tracking, IMU fusion and pan/tilt control for a walking robot's camera head"};
  app.set_version_flag("--version", std::string(epichead::firmware_iface::program_version()));
  app.require_subcommand(1);
  app.footer("Run 'epichead <command> --help' for the options of a command.");

  std::vector<std::pair<CLI::App*, CommandAction>> actions;
  auto& registry = command_registry();
  actions.reserve(registry.size());
  for (auto& command : registry) {
    CLI::App* sub = app.add_subcommand(command.name, command.summary);
    actions.emplace_back(sub, command.setup(*sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto& [sub, action] : actions) {
    if (sub->parsed()) {
      try {
        return action();
      } catch (const std::exception& e) {
        return fail(sub->get_name(), e.what());
      }
    }
  }
  return 1;
}
