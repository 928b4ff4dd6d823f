#include "relief_snake/input_checks.hpp"

#include <cmath>
#include <sstream>

#include "relief_snake/error.hpp"

namespace relief_snake {

namespace {

std::string shown(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

}  // namespace

double checked_step_height(double h, const std::string& name) {
  if (!std::isfinite(h) || !(h > 0))
    throw Error(name + " must be a finite number > 0 (got " + shown(h) +
                "), or left to the engine to estimate; measure the relief's step with the measure tool");
  return h;
}

double checked_w_int(double w_int, const std::string& name) {
  if (!std::isfinite(w_int) || !(w_int > 0) || w_int > 1)
    throw Error(name + " must be in (0, 1] (got " + shown(w_int) +
                "), or left to the engine; try 0.25, then halve it if concavities are missed");
  return w_int;
}

void check_pick_count(std::size_t count, bool closed) {
  const std::size_t needed = closed ? 3 : 2;
  if (count < needed)
    throw Error(std::string(closed ? "a closed contour" : "an open contour") + " needs at least " +
                std::to_string(needed) + " picked vertices (got " + std::to_string(count) +
                "); pick vertices around the relief");
}

int checked_input_vertex(const Mesh& mesh, std::int64_t index, const std::string& what) {
  const std::size_t n = mesh.input_vertex_count();
  if (index < 0 || static_cast<std::size_t>(index) >= n)
    throw Error(what + " " + std::to_string(index) + " is not a vertex index, out of range: the mesh file has " +
                std::to_string(n) + " vertices (indices are 0-based)");
  const int v = mesh.input_to_mesh(static_cast<std::size_t>(index));
  if (v < 0)
    throw Error(what + " " + std::to_string(index) +
                " is in no face of the mesh (unused or in a refused face); pick a vertex on the surface");
  return v;
}

}  // namespace relief_snake
