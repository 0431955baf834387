#pragma once
#include <stdexcept>
#include <string>

namespace mp {
// Every failure the user can cause (bad scene, missing device, kernel build
// failure, out of device memory) is reported as mp::Error with a one-line,
// human-readable message. The Python module turns it into RuntimeError.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
}  // namespace mp
