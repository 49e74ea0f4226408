// Shared pieces of the `tippe` subcommands: how one registers, how errors map to exit codes.
#pragma once

#include <algorithm>
#include <exception>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include "include/tippe/tippe.h"

#include "harness/io/interrupt.h"
#include "harness/io/output_dir.h"
#include "harness/io/scene_io.h"
#include "engines/core/registry.h"

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
// (SceneError, UsageError, InputError), an unusable output path (OutputError) and an engine module
// that cannot be loaded (EngineLoadError) -> 2; a signal that ended the command cleanly
// (Interrupted) -> 128 + its number, as a shell reports a signal; anything else is a bug ->
// kInternalExit, said as "internal". 1 is a failing gate's alone, so that CI can
// tell "the settings fail" from "tippe broke".
inline constexpr int kInternalExit = 3;

// The most parallel runs --jobs takes: far above any machine's cores, and a range a user can read
// in the message (CLI::PositiveNumber answered --jobs 0 with a 309-digit bound).
inline constexpr int kMaxJobs = 4096;

inline int error_exit(const std::exception_ptr& e, bool print = true) {
  try {
    std::rethrow_exception(e);
  } catch (const SceneError& x) {
    if (print) std::cerr << "tippe: error: " << x.what() << "\n";
    return 2;
  } catch (const UsageError& x) {
    if (print) std::cerr << "tippe: error: " << x.what() << "\n";
    return 2;
  } catch (const InputError& x) {  // the library's (library/verbs.h), as UsageError
    if (print) std::cerr << "tippe: error: " << x.what() << "\n";
    return 2;
  } catch (const OutputError& x) {
    if (print) std::cerr << "tippe: error: " << x.what() << "\n";
    return 2;
  } catch (const EngineLoadError& x) {  // an engine's module missing or unloadable: the installation's fault, said as such
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
// The name in `names` nearest to `word` by edit distance (insertions, deletions, substitutions),
// when it is close enough to be a typo (at most a third of the word's length, and at least 1);
// "" otherwise.
inline std::string nearest_name(const std::string& word, const std::vector<std::string>& names) {
  std::string best;
  size_t best_d = word.size() / 3 + 2;  // one past the largest distance taken
  for (const std::string& n : names) {
    std::vector<size_t> row(n.size() + 1);
    for (size_t j = 0; j <= n.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= word.size(); ++i) {
      size_t diag = row[0];
      row[0] = i;
      for (size_t j = 1; j <= n.size(); ++j) {
        const size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (word[i - 1] == n[j - 1] ? 0 : 1)});
        diag = up;
      }
    }
    if (row[n.size()] < best_d) {
      best_d = row[n.size()];
      best = n;
    }
  }
  return best;
}

// `tippe info`'s "can invert" line: whether 1 - alpha < A/C < 1 + alpha, as a true sentence.
std::string inversion_condition_text(double alpha, double ratio);

Command setup_run(CLI::App& app);
Command setup_export_mjcf(CLI::App& app);
Command setup_import_mjcf(CLI::App& app);
Command setup_info(CLI::App& app);
Command setup_compare(CLI::App& app);  // and setup_report, in cli_compare.cpp
Command setup_report(CLI::App& app);
Command setup_sweep(CLI::App& app);
Command setup_gate(CLI::App& app);
Command setup_advise(CLI::App& app);

// The common SCENE.toml positional and repeatable --set KEY=VALUE option.
inline void add_scene_options(CLI::App* sub, std::string& scene, std::vector<std::string>& sets) {
  sub->add_option("scene", scene, "Scene file (TOML)")->required();
  // allow_extra_args(false): each --set takes exactly one KEY=VALUE, so the scene may follow it.
  sub->add_option("--set", sets, "Override a scene key, e.g. contact.mu=0.5 (repeatable)")
      ->allow_extra_args(false)
      ->take_all();
}

}  // namespace tippe::cli
