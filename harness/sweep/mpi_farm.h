// The MPI side of `tippe sweep`: whether an MPI launcher started this process, the MPI session, and the TaskFarm over its ranks.
#pragma once

#include <memory>
#include <string>

#include "harness/measure/task_farm.h"

namespace tippe {

// The world size an MPI launcher (mpirun, mpiexec, srun) announced in the environment; 0 when
// none did. Read before MPI_Init, so that a plain `tippe sweep` never starts MPI.
int mpi_launch_size();

// Whether this build has MPI, and which (e.g. "Open MPI v4.1.4"); "" without.
std::string mpi_library_version();

#ifdef TIPPE_HAVE_MPI
// MPI_Init for the life of the object, MPI_Finalize after (also when an exception unwinds).
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

// Rank 0 coordinates, ranks 1..size-1 work; every call is collective over MPI_COMM_WORLD.
std::unique_ptr<TaskFarm> make_mpi_farm(const MpiSession& session);
#endif

}  // namespace tippe
