// Shared pieces of the `tippe` subcommands: how one registers, how errors map to exit codes.
#pragma once

#include <exception>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "interrupt.h"
#include "output_dir.h"
#include "scene_io.h"

namespace tippe::cli {

// Invalid input found by a subcommand (unknown engine, bad setting): exit code 2, like SceneError.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A subcommand adds itself to the app and returns what to run once the command line is parsed.
// The action returns the exit code; exceptions are mapped by main (error_exit).
using Action = std::function<int()>;
struct Command {
  CLI::App* sub = nullptr;
  Action action;
};
using Setup = Command (*)(CLI::App& app);

// A subcommand's exception as an exit code, its message on stderr when `print`: bad input
// (SceneError, UsageError) and an unusable output path (OutputError) -> 2; a signal that ended
// the command cleanly (Interrupted) -> 128 + its number, as a shell reports a signal; anything
// else is a bug -> kInternalExit, said as "internal". 1 is a failing gate's alone, so that CI can
// tell "the settings fail" from "tippe broke".
inline constexpr int kInternalExit = 3;

inline int error_exit(const std::exception_ptr& e, bool print = true) {
  try {
    std::rethrow_exception(e);
  } catch (const SceneError& x) {
    if (print) std::cerr << "tippe: error: " << x.what() << "\n";
    return 2;
  } catch (const UsageError& x) {
    if (print) std::cerr << "tippe: error: " << x.what() << "\n";
    return 2;
  } catch (const OutputError& x) {
    if (print) std::cerr << "tippe: error: " << x.what() << "\n";
    return 2;
  } catch (const Interrupted& x) {
    if (print) std::cerr << "tippe: " << x.what() << "; no output half-written\n";
    return 128 + x.signal();
  } catch (const std::exception& x) {
    if (print) std::cerr << "tippe: error: internal: " << x.what() << "\n";
    return kInternalExit;
  }
}

// One function per subcommand, each in its own cli_NAME.cpp; main.cpp lists them.
Command setup_run(CLI::App& app);
Command setup_export_mjcf(CLI::App& app);
Command setup_import_mjcf(CLI::App& app);
Command setup_info(CLI::App& app);
Command setup_compare(CLI::App& app);  // and setup_report, in cli_compare.cpp
Command setup_report(CLI::App& app);
Command setup_sweep(CLI::App& app);
Command setup_gate(CLI::App& app);

// The common SCENE.toml positional and repeatable --set KEY=VALUE option.
inline void add_scene_options(CLI::App* sub, std::string& scene, std::vector<std::string>& sets) {
  sub->add_option("scene", scene, "Scene file (TOML)")->required();
  // allow_extra_args(false): each --set takes exactly one KEY=VALUE, so the scene may follow it.
  sub->add_option("--set", sets, "Override a scene key, e.g. contact.mu=0.5 (repeatable)")
      ->allow_extra_args(false)
      ->take_all();
}

}  // namespace tippe::cli
