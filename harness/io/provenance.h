// Build provenance compiled into the harness (compiler, flags, commit).
#pragma once

#include <string>

namespace tippe {

struct BuildInfo {
  // The commit the build was made from (12 hex digits), "-dirty" appended when the tree's tracked
  // files differed from it at the build, "unknown" outside a git checkout.
  std::string git_commit;
  std::string compiler;
  std::string cxx_flags;
};

BuildInfo build_info();

}  // namespace tippe
