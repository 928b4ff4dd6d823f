#pragma once
// The engine's one error type: a one-line message that says what is wrong and what to do.
#include <stdexcept>
#include <string>

namespace relief_snake {

/// Thrown for bad input (mesh, picks, parameters) and for a segmentation that
/// cannot produce a meaningful result. `what()` is one line, meant for the user.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace relief_snake
