// The message of the std::invalid_argument a call throws, or "" when it throws none: tests assert
// on what an error says, not only that there is one.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

inline std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}
