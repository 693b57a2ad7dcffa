#pragma once
// One exception type for every failure Kartograf reports: what was being done, on what, and why.
#include <stdexcept>
#include <string>

namespace kartograf {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws Error(message) when condition is false. Used for input validation, never for asserts.
inline void require(bool condition, const std::string& message) {
  if (!condition) throw Error(message);
}

}  // namespace kartograf
