#pragma once
// Numbers typed on the command line, read one way for every command (segment, measure, extract):
// the whole text must be the number (std::strtod / std::strtoll, C locale), and a problem is one
// line naming the argument. Usage is the command's usage-error type (exit code 2).
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace relief_snake::cli {

/// `text` as a finite double; Usage(message) otherwise.
template <class Usage>
double parse_number(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) throw Usage(what + " must be a number, got '" + text + "'");
  if (!std::isfinite(value) && errno != ERANGE) throw Usage(what + " must be a finite number, got '" + text + "'");
  if (errno == ERANGE && std::abs(value) > 1)
    throw Usage(what + " " + text + " is too large for double precision (beyond 1.8e308)");
  if (errno == ERANGE)
    throw Usage(what + " " + text + " is too small for double precision (below 2.2e-308); give it in mesh units");
  return value;
}

/// `text` as an index >= 0 (0-based); Usage(message) otherwise.
template <class Usage>
std::int64_t parse_index(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
    throw Usage(what + " must be a whole number, got '" + text + "'");
  if (value < 0) throw Usage(what + " must be >= 0 (indices are 0-based), got " + text);
  return value;
}

}  // namespace relief_snake::cli
