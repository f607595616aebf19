#pragma once
/// \file version.hpp
/// \brief The version of the contactrom libraries, as the build set it (CMake's
/// project version): the same text for `contactrom --version`, the `created_by`
/// attribute of the files it writes, and Python's `contactrom.__version__`.
#include <string>

namespace contactrom {

/// \brief The version, "MAJOR.MINOR.PATCH" (e.g. "0.2.0").
std::string version();

}  // namespace contactrom
