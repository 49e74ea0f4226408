// The one entry point of the MPI module (lib/tippe/libtippe_mpi.so), the only part of tippe that links the MPI library.
#pragma once

#include <string>

#include "harness/measure/task_farm.h"

namespace tippe {

// What the module gives tippe (harness/sweep/mpi_session.cpp opens it when a launcher started the
// process): a process that no launcher started, a reference run for one, never maps libmpi and its
// seven libraries, which cost the loader about as much as the rest of tippe's libraries.
struct MpiModule {
  void (*init)(int* rank, int* size);          // MPI_Init unless done; errors as codes; rank and world size
  void (*finalize)();                          // MPI_Finalize unless done
  TaskFarm* (*make_farm)(int rank, int size);  // rank 0 coordinates; the caller owns it
  std::string (*library_version)();            // e.g. "Open MPI v4.1.4"
};

inline constexpr const char* kMpiModuleFile = "libtippe_mpi.so";
inline constexpr const char* kMpiModuleEntry = "tippe_mpi_module";

}  // namespace tippe

extern "C" __attribute__((visibility("default"))) const tippe::MpiModule* tippe_mpi_module();
