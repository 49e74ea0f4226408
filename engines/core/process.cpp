// The process set-up for engine libraries (engines/core/process.h).
#include "engines/core/process.h"

#include <stdlib.h>  // setenv (POSIX)

namespace tippe {

void prepare_process_for_engines() {
  // OpenBLAS reads the variable in its constructor, when the first engine library that links it is
  // loaded: this must come before. overwrite = 0: the user's own value stands.
  ::setenv("OPENBLAS_NUM_THREADS", "1", 0);
}

}  // namespace tippe
