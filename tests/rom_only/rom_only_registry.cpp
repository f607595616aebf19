// Linked with contactrom::rom alone (tests/CMakeLists.txt): asking for a baseline
// method must name the library to link, not say "unknown online method".
#include <iostream>
#include <string>

#include <contactrom/core/errors.hpp>
#include <contactrom/rom/online_methods.hpp>

int main() {
  try {
    (void)contactrom::rom::online_method("cpg");
  } catch (const contactrom::InputError& e) {
    const std::string what = e.what();
    std::cout << what << "\n";
    return what.find("contactrom::baselines") != std::string::npos ? 0 : 1;
  }
  std::cout << "cpg found without contactrom::baselines\n";
  return 1;
}
