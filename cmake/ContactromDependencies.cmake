# Finds the Debian-packaged dependencies of the build; those without a CMake
# config (CHOLMOD, gmsh, Ipopt) become IMPORTED targets in
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
