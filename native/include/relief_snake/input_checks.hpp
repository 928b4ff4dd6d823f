#pragma once
// The checks of what a user gives the engine (h, W_int, picks), in one place: Segmenter::segment
// runs them, and the front ends (CLI, Python module) call them only to fail early, translating
// the Error into their own kind (a usage error, a ValueError). Each throws Error with one line
// that says what to do; `name` is how the caller spells the option ("--step-height", "step_height").
#include <cstdint>
#include <string>

#include "relief_snake/mesh.hpp"

namespace relief_snake {

/// A given step height h: finite and > 0 (a front end translates its "auto" into kAuto itself).
double checked_step_height(double h, const std::string& name = "step height h");

/// A given W_int: in (0, 1].
double checked_w_int(double w_int, const std::string& name = "W_int");

/// Enough picks for a closed (>= 3) or open (>= 2) contour.
void check_pick_count(std::size_t count, bool closed);

/// Input (file) vertex `index` as a vertex of `mesh`: it must exist and lie on a face. `what`
/// names it in the message ("pick").
int checked_input_vertex(const Mesh& mesh, std::int64_t index, const std::string& what = "pick");

}  // namespace relief_snake
