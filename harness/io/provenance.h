// Build provenance compiled into the harness (compiler, flags, commit).
#pragma once

#include <string>

namespace tippe {

struct BuildInfo {
  std::string git_commit;
  std::string compiler;
  std::string cxx_flags;
};

BuildInfo build_info();

}  // namespace tippe
