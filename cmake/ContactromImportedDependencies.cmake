# IMPORTED targets for the dependencies without a CMake package: CHOLMOD (found by
# header and library name), Ipopt (pkg-config) and LAPACK (CMake's FindLAPACK).
# Included by the build and by the installed contactromConfig.cmake.
if(NOT TARGET SuiteSparse::CHOLMOD)
  find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
  find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
  find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig REQUIRED)
  add_library(SuiteSparse::CHOLMOD INTERFACE IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${CHOLMOD_LIBRARY};${SUITESPARSECONFIG_LIBRARY}")
endif()

# LAPACK (dpotri in fom/sparse_cholesky.cpp): the system's liblapack.so.3, OpenBLAS's
# where it is installed (tools/setup.sh), as under CHOLMOD.
if(NOT TARGET LAPACK::LAPACK)
  find_package(LAPACK REQUIRED)
endif()

if(NOT TARGET PkgConfig::IPOPT)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(IPOPT REQUIRED IMPORTED_TARGET ipopt)
endif()
