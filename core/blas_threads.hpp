#pragma once
/// \file blas_threads.hpp
/// \brief The number of threads of the system BLAS (OpenBLAS, when it is the one
/// loaded), set once per process by a program that parallelises above it.

namespace contactrom {

/// \brief Runs OpenBLAS on one thread unless the user chose a number
/// (`OPENBLAS_NUM_THREADS`, `GOTO_NUM_THREADS` or `OMP_NUM_THREADS` set).
///
/// The offline stage already runs one FOM per thread (and MPI one per rank); BLAS
/// threads under them would only compete for the same cores. One BLAS thread also
/// gives the same bits as a single-threaded BLAS. Does nothing when the loaded BLAS is
/// not OpenBLAS (the symbol `openblas_set_num_threads` is looked up at run time, no
/// link dependency). Changes a process-wide setting: the CLI calls it at start-up;
/// a library user decides for their own process.
/// \returns whether OpenBLAS was found and set to one thread.
bool use_one_blas_thread_by_default();

}  // namespace contactrom
