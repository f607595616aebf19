#pragma once
// For test programs that compare the library's results with the CLI's bit for bit:
// the BLAS runs as the CLI runs it (one OpenBLAS thread unless OPENBLAS_NUM_THREADS is
// set; core/blas_threads.hpp), as docs/library.md asks of a library user who wants the
// CLI's bits. Include it once per test program, after <boost/test/unit_test.hpp>.
#include <contactrom/core/blas_threads.hpp>

struct ContactromCliBlasThreads {
  ContactromCliBlasThreads() { contactrom::use_one_blas_thread_by_default(); }
};

BOOST_TEST_GLOBAL_FIXTURE(ContactromCliBlasThreads);
