#pragma once
// The message of the InputError that f() throws, "" if it throws none.
#include <string>

#include <contactrom/core/errors.hpp>

namespace contactrom::test {

template <typename F>
std::string input_error_of(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace contactrom::test
