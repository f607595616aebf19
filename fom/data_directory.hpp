#pragma once
/// \file data_directory.hpp
/// \brief Where the shipped data (problem files, meshes) are found, for a build
/// tree and an installed copy alike.
#include <string>

namespace contactrom::fom {

/// \brief Folder `<root>/share/contactrom/<sub>` of the shipped data, looked up in
/// this order:
/// 1. the environment variable `env` (e.g. `CONTACTROM_PROBLEM_DIR`) when set and
///    not empty, as is;
/// 2. `share/contactrom/<sub>` in the folder of the binary holding this code (the
///    program, or the shared library) or one of its ancestors: an installed
///    `P/bin/contactrom` finds `P/share/contactrom`, a build tree's
///    `build/tools/contactrom` finds `build/share/contactrom` (links to the
///    sources, made by CMake);
/// 3. the data folder of the configured install prefix
///    (`CMAKE_INSTALL_PREFIX/share/contactrom/<sub>`), returned even if missing
///    so that error messages name it.
std::string data_directory(const std::string& sub, const char* env);

}  // namespace contactrom::fom
