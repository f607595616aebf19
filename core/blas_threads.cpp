#include <contactrom/core/blas_threads.hpp>

#include <dlfcn.h>

#include <cstdlib>
#include <initializer_list>

namespace contactrom {

bool use_one_blas_thread_by_default() {
  for (const char* name : {"OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"})
    if (std::getenv(name)) return false;
  // The BLAS is libblas.so.3, whichever library Debian's alternatives point it to;
  // OpenBLAS (loaded through it) exports this setter, the reference BLAS does not.
  using SetThreads = void (*)(int);
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (!set) return false;
  set(1);
  return true;
}

}  // namespace contactrom
