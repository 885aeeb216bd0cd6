#pragma once
#include <stdexcept>
#include <string>

namespace sf {

// Bad user input (files, arguments, sizes that don't fit): the CLI prints the one-line message
// and exits with code 2.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

// An OpenCL failure (build error, out of resources, lost device): exit code 3.
class DeviceError : public std::runtime_error {
 public:
  explicit DeviceError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace sf
