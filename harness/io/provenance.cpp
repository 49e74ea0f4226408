// Build provenance compiled into the harness (compiler, flags, commit).
#include "harness/io/provenance.h"

// TIPPE_GIT_COMMIT, written into the build tree at every build by cmake/provenance.cmake.
#include "tippe_git_commit.h"

namespace tippe {

BuildInfo build_info() { return {TIPPE_GIT_COMMIT, TIPPE_COMPILER, TIPPE_CXX_FLAGS}; }

}  // namespace tippe
