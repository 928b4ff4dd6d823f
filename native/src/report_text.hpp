#pragma once
// Small helpers the stages share for their reports: numbers in messages and wall times.
#include <chrono>
#include <sstream>
#include <string>

namespace relief_snake {

/// x with `precision` significant digits, as messages and notes print it.
inline std::string fmt(double x, int precision = 4) {
  std::ostringstream s;
  s.precision(precision);
  s << x;
  return s.str();
}

/// Seconds of wall time since `start`.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace relief_snake
