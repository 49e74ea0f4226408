// The `tippe` command line: parses the arguments and runs one subcommand (each lives in a cli_*.cpp).
#include <algorithm>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "harness/cli/cli.h"
#include "harness/io/progress.h"
#include "harness/io/provenance.h"
#include "engines/core/process.h"
#include "engines/core/registry.h"
#include "include/tippe/tippe.h"
#include "harness/io/scene_io.h"

int main(int argc, char** argv) {
  using namespace tippe;
  prepare_process_for_engines();  // first: before any thread or engine module
  CLI::App app{"tippe: the tippe-top verification bench"};
  app.require_subcommand(1);
  // Every subcommand takes --quiet, also after its own options: subcommands made after
  // fallthrough() hand an option they do not know up to here.
  bool quiet = false;
  app.add_flag("-q,--quiet", quiet, "No progress on stderr (errors and warnings still go there)");
  app.fallthrough();
  // Version, commit, the reference's library and each engine's module (from the engine registry).
  // An engine's library version is its module's to say, once loaded (every record carries it):
  // --version loads none, so that it costs no engine library's start-up.
  app.set_version_flag("--version", [] {
    const BuildInfo b = build_info();
    std::string text = "tippe " + tippe::version() + " (commit " + b.git_commit + ", " + b.compiler + ")";
    for (const std::string& name : available_engines()) {
      text += "\n  " + name + ": ";
      if (!engines_in_modules() || engine_loaded(name)) text += engine_info(name).version;
      else text += "module " + engine_module_file(name) + ", loaded on first use";
    }
    return text;
  });
  // Adding a subcommand: write cli_NAME.cpp with setup_NAME, declare it in cli.h, list it here.
  const cli::Setup commands[] = {cli::setup_run, cli::setup_export_mjcf, cli::setup_import_mjcf, cli::setup_info,
                                  cli::setup_compare, cli::setup_report, cli::setup_sweep,
                                  cli::setup_gate, cli::setup_advise};
  std::map<const CLI::App*, cli::Action> actions;
  for (cli::Setup setup : commands) {
    cli::Command c = setup(app);
    actions[c.sub] = std::move(c.action);
  }

  // A word where a subcommand belongs that is none: say so, with the nearest name, instead of
  // CLI11's "arguments were not expected".
  if (argc > 1 && argv[1][0] != '-') {
    const std::string word = argv[1];
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(sub->get_name());
    if (std::find(names.begin(), names.end(), word) == names.end()) {
      std::cerr << "tippe: error: unknown subcommand '" << word << "'";
      const std::string near = cli::nearest_name(word, names);
      if (!near.empty()) std::cerr << " (did you mean '" << near << "'?)";
      std::cerr << "; the subcommands are:";
      for (const std::string& n : names) std::cerr << " " << n;
      std::cerr << "\n(run with --help for usage)\n";
      return 2;
    }
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
    std::cerr << "tippe: error: " << e.what() << "\n(run with --help for usage)\n";
    return 2;
  }

  set_progress_mode(progress_mode_for_stderr(quiet));
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
