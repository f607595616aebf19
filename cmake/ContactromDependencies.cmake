# Finds the Debian-packaged dependencies of the build; those without a CMake
# config (CHOLMOD, Ipopt) become IMPORTED targets in
# ContactromImportedDependencies.cmake, which the installed package reuses.
find_package(Eigen3 3.4 REQUIRED CONFIG)
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(Threads REQUIRED)
find_package(nlohmann_json 3 REQUIRED CONFIG)
find_package(tomlplusplus CONFIG REQUIRED)
find_package(CLI11 CONFIG QUIET)
if(NOT CLI11_FOUND)
  find_path(CLI11_INCLUDE_DIR CLI/CLI.hpp REQUIRED)
  add_library(CLI11::CLI11 INTERFACE IMPORTED)
  set_target_properties(CLI11::CLI11 PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${CLI11_INCLUDE_DIR}")
endif()
include(ContactromImportedDependencies)
# gmsh: its C API header, and the library that fom/gmsh_api.cpp opens when a mesh is
# first made (nothing links it, so an installed contactrom does not look for it). The
# definitions give gmsh_api.cpp the library's path and, as a fallback, its file name.
find_path(GMSH_INCLUDE_DIR gmshc.h REQUIRED)
find_library(GMSH_LIBRARY gmsh REQUIRED)
get_filename_component(CONTACTROM_GMSH_REALPATH "${GMSH_LIBRARY}" REALPATH)
get_filename_component(CONTACTROM_GMSH_NAME "${CONTACTROM_GMSH_REALPATH}" NAME)
set(CONTACTROM_GMSH_DEFINITIONS CONTACTROM_GMSH_LIBRARY="${CONTACTROM_GMSH_REALPATH}"
    CONTACTROM_GMSH_NAME="${CONTACTROM_GMSH_NAME}")
