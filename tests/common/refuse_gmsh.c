/* LD_PRELOAD shim for tests/fom/test_gmsh_on_demand.cpp: dlopen() of any library
 * whose name contains "gmsh" fails (as on a machine without the gmsh library); every
 * other dlopen() is the C library's. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <string.h>

void* dlopen(const char* file, int flags) {
  static void* (*real_dlopen)(const char*, int) = NULL;
  if (!real_dlopen) real_dlopen = (void* (*)(const char*, int))dlsym(RTLD_NEXT, "dlopen");
  if (file && strstr(file, "gmsh")) return NULL;
  return real_dlopen(file, flags);
}
