// The `tippe` command line: parses the arguments and runs one subcommand (each lives in a cli_*.cpp).
#include <iostream>
#include <map>

#include "cli.h"
#include "scene_io.h"

int main(int argc, char** argv) {
  using namespace tippe;
  CLI::App app{"tippe: the tippe-top verification bench"};
  app.require_subcommand(1);
  // Adding a subcommand: write cli_NAME.cpp with setup_NAME, declare it in cli.h, list it here.
  const cli::Setup commands[] = {cli::setup_run, cli::setup_export_mjcf, cli::setup_import_mjcf, cli::setup_info,
                                  cli::setup_compare, cli::setup_report, cli::setup_sweep,
                                  cli::setup_gate};
  std::map<const CLI::App*, cli::Action> actions;
  for (cli::Setup setup : commands) {
    cli::Command c = setup(app);
    actions[c.sub] = std::move(c.action);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "tippe: error: " << e.what() << "\n(run with --help for usage)\n";
    return 2;
  }

  install_interrupt_handlers();
  try {
    const int code = actions.at(app.get_subcommands().front())();
    // A signal deferred while the last unit was committed still ends the command as a signal.
    check_interrupted();
    return code;
  } catch (const std::exception&) {
    return cli::error_exit(std::current_exception());
  }
}
