// `epichead`: the single command-line entry point; dispatches to the registered commands.
#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>
#include <string_view>

#include "command.h"
#include "printable.h"
#include "progress.h"
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
  // The reason holds file names and text from files: shown escaped (printable.h). On a clean
  // line: a progress line being drawn is wiped first.
  Progress::clear_current();
  std::cerr << "epichead " << command << ": " << printable(reason) << "\n";
  return kRuntimeErrorExit;
}

namespace {

// A command line that does not parse: one line saying why, the usage line of the command (or
// of the program), exit code 2 (the convention of getopt tools; CLI11's own codes are 105-109).
int usage_error(const CLI::App& app, const std::vector<std::pair<CLI::App*, CommandAction>>& actions, int argc,
                char** argv, const std::string& what) {
  const CLI::App* command = nullptr;
  for (const auto& [sub, action] : actions)
    if (sub->parsed()) command = sub;
  CLI::Formatter formatter;
  if (!command && argc > 1 && argv[1][0] != '-') {
    // The first word is not an option and no command took it: it is a command we do not have.
    std::string names;
    for (const auto& [sub, action] : actions) names += (names.empty() ? "" : ", ") + sub->get_name();
    std::cerr << "epichead: unknown command '" << printable(argv[1]) << "' (commands: " << names << ")\n"
              << formatter.make_usage(&app, "epichead");
  } else if (!command && argc > 1 && std::string_view(argv[1]) != "--help" && std::string_view(argv[1]) != "-h" &&
             std::string_view(argv[1]) != "--version") {
    // An option before any command: CLI11 reports the missing command, the option is the mistake.
    std::cerr << "epichead: unknown option '" << printable(argv[1]) << "'\n"
              << formatter.make_usage(&app, "epichead") << "Run 'epichead --help' for the commands.\n";
  } else if (command) {
    std::cerr << "epichead " << command->get_name() << ": " << printable(what) << "\n"
              << formatter.make_usage(command, "epichead " + command->get_name())
              << "Run 'epichead " << command->get_name() << " --help' for the options.\n";
  } else {
    std::cerr << "epichead: " << printable(what) << "\n" << formatter.make_usage(&app, "epichead")
              << "Run 'epichead --help' for the commands.\n";
  }
  return kUsageExit;
}

}  // namespace
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
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return usage_error(app, actions, argc, argv, e.what());
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
  return kRuntimeErrorExit;
}
