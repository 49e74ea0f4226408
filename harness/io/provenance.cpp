// Build provenance compiled into the harness (compiler, flags, commit).
#include "harness/io/provenance.h"

namespace tippe {

BuildInfo build_info() { return {TIPPE_GIT_COMMIT, TIPPE_COMPILER, TIPPE_CXX_FLAGS}; }

}  // namespace tippe
