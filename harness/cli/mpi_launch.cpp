// What an MPI launcher says in the environment, readable in every build (with or without MPI).
#include <cstdlib>
#include <string>

#include "harness/sweep/mpi_farm.h"

namespace tippe {

int mpi_launch_size() {
  // Open MPI's mpirun, PMIx launchers (srun --mpi=pmix, prun), PMI-1/2 (MPICH's hydra, srun --mpi=pmi2).
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* v = std::getenv(name);
    if (v && *v) {
      char* end = nullptr;
      const long n = std::strtol(v, &end, 10);
      if (*end == '\0' && n > 0) return static_cast<int>(n);
    }
  }
  // PMIx does not always export a size; a rank alone still means a launcher.
  return std::getenv("PMIX_RANK") || std::getenv("PMI_RANK") ? 1 : 0;
}

#ifndef TIPPE_HAVE_MPI
std::string mpi_library_version() { return ""; }
#endif

}  // namespace tippe
