// What a program that runs engines sets up in its process before the first engine library loads.
#pragma once

namespace tippe {

// Readies the process for engine libraries before any is loaded: the first call of a program that
// runs engines (tippe's main), while it is still single-threaded (setenv beside another thread's
// getenv is a race). Sets OPENBLAS_NUM_THREADS=1 unless the environment already sets it: Siconos'
// numerics and Simbody's LAPACK link Debian's OpenBLAS (pthread build), whose load starts a thread
// team that the bench's single-threaded runs only pay for. Siconos' adapter sets one thread once the
// library is loaded, yet a run still paid ~0.03 s and 9 % a simulated second for the team
// (BENCHMARKS.md, Siconos). A value the user set is kept: theirs to say beside a cost.
void prepare_process_for_engines();

}  // namespace tippe
