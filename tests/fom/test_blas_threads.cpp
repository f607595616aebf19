// use_one_blas_thread_by_default (core/blas_threads.hpp) in a process that loads the
// system BLAS through CHOLMOD, as the CLI does (hence here and not in tests/core, whose
// programs link no BLAS): OpenBLAS is set to one thread unless the user chose a count;
// with another BLAS nothing happens.
#define BOOST_TEST_MODULE fom_blas_threads
#include <boost/test/unit_test.hpp>

#include <dlfcn.h>

#include <cstdlib>

#include <contactrom/core/blas_threads.hpp>
#include <contactrom/fom/sparse_cholesky.hpp>

namespace {

using GetThreads = int (*)();
using SetThreads = void (*)(int);

void unset_thread_variables() {
  for (const char* name : {"OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"}) unsetenv(name);
}

}  // namespace

BOOST_AUTO_TEST_CASE(openblas_runs_one_thread_unless_the_user_chose) {
  contactrom::fom::SparseCholesky keep_cholmod_linked;  // the BLAS is loaded with CHOLMOD
  const auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (!get || !set) {
    BOOST_TEST_MESSAGE("the loaded BLAS is not OpenBLAS: the call must do nothing");
    unset_thread_variables();
    BOOST_TEST(!contactrom::use_one_blas_thread_by_default());
    return;
  }
  set(2);
  setenv("OPENBLAS_NUM_THREADS", "2", 1);  // the user's choice is kept
  BOOST_TEST(!contactrom::use_one_blas_thread_by_default());
  BOOST_TEST(get() == 2);
  unset_thread_variables();
  setenv("OMP_NUM_THREADS", "2", 1);
  BOOST_TEST(!contactrom::use_one_blas_thread_by_default());
  BOOST_TEST(get() == 2);
  unset_thread_variables();
  BOOST_TEST(contactrom::use_one_blas_thread_by_default());
  BOOST_TEST(get() == 1);
}
