#include <contactrom/core/version.hpp>

namespace contactrom {

std::string version() { return CONTACTROM_VERSION; }

}  // namespace contactrom
