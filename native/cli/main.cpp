// relief-snake: command-line front end of the engine.
//
//   relief-snake segment MESH --picks I,J,K,... --step-height H [options]   -> JSON result
//   relief-snake measure MESH I J                                          -> distance
//   relief-snake info MESH                                                 -> mesh report
//
// Exit codes: 0 success, 1 bad input or failed segmentation, 2 usage error.
// Every error is exactly one line on stderr: "relief-snake: <message>".
#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "extract_command.hpp"
#include "multi_command.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/option_table.hpp"
#include "relief_snake/result_json.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/segment.hpp"

namespace rs = relief_snake;
using nlohmann::json;

namespace {

const char* kUsage =
    "usage:\n"
    "  relief-snake segment MESH --picks I,J,K,... [--step-height H|auto] [options]\n"
    "  relief-snake detect MESH [--region-vertices FILE] [--min-area A] [--out FILE] [options]\n"
    "  relief-snake measure MESH I J\n"
    "  relief-snake info MESH\n"
    "  relief-snake extract MESH RESULT.json --out DIR [options]\n"
    "  relief-snake --help\n"
    "\n"
    "MESH is an OBJ, PLY, STL or OFF file. Vertex indices (picks, I, J) are 0-based\n"
    "indices into the file's vertices, in file order.\n"
    "  --allow-partial        (any command) load the readable part of a truncated or inconsistent\n"
    "                         file, skipping invalid faces and vertices; what was skipped is reported\n"
    "\n"
    "segment: find the outline of the relief around (or beside) the picked vertices.\n"
    "  --picks I,J,K,...      picked vertices in order around the relief (>= 3; >= 2 with --open);\n"
    "                         repeat it for several reliefs: one snake each, written as one document\n"
    "                         with a result per relief and their overlaps (docs/result-format.md)\n"
    "  --step-height H|auto   the relief's step height, in mesh units (> 0; see 'measure'); auto (the\n"
    "                         default): estimated from the picks and the surface\n"
    "  --w-int W|auto         internal-energy weight for refinement, in (0, 1]; auto (the default):\n"
    "                         the engine tries 0.25, 0.5 and 1 until its self-check holds\n"
    "  --open                 open contour that ends on the mesh boundary\n"
    "  --relief-side left|right|auto  with --open: side of the relief along the pick order\n"
    "                         (default auto: the side that rises)\n"
    "  --max-iterations N     iteration cap per phase (default 3000)\n"
    "  --option NAME=VALUE    set an advanced option (repeatable; see 'advanced options' below)\n"
    "  --out FILE             write the JSON result to FILE instead of stdout\n"
    "  --quiet                no progress on stderr\n"
    "measure: straight-line distance between vertices I and J (to estimate H).\n"
    "info: what intake made of the mesh (merged, triangulated, refused faces, ...).\n"
    "\n"
    "exit codes: 0 success, 1 bad input or failed segmentation, 2 usage error,\n"
    "  3 result written but doubtful or stopped at the iteration cap (see its status and message)\n";

/// A malformed command line (exit code 2).
struct UsageError : std::runtime_error {
  explicit UsageError(const std::string& message) : std::runtime_error(message) {}
};

// --- advanced options (--option NAME=VALUE) ------------------------------------
// The engine's option table (relief_snake/option_table.hpp) parses and range-checks
// each value; here a bad one is a usage error (exit 2).

std::string advanced_options_help() {
  std::string text =
      "advanced options of segment (--option NAME=VALUE, repeatable; docs/design.md says which depart from the paper):\n";
  const rs::Options defaults;
  for (const rs::OptionInfo& a : rs::advanced_options()) {
    std::string line = std::string("  ") + a.name + " ";
    line.resize(std::max<std::size_t>(line.size(), 30), ' ');
    text += line + a.range + " (default " + rs::advanced_option_json(defaults, a.name) + "): " + a.help + "\n";
  }
  return text;
}

/// Applies "NAME=VALUE" to the options.
void set_advanced_option(rs::Options& options, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  const std::string name = assignment.substr(0, eq);
  if (eq == std::string::npos || name.empty())
    throw UsageError("--option needs NAME=VALUE, got '" + assignment + "'; valid names: " +
                     rs::advanced_option_names());
  bool known = false;
  for (const rs::OptionInfo& a : rs::advanced_options()) known = known || name == a.name;
  if (!known) throw UsageError("unknown --option '" + name + "'; valid names: " + rs::advanced_option_names());
  try {
    rs::set_advanced_option(&options, name, assignment.substr(eq + 1));
  } catch (const rs::Error& e) {
    throw UsageError(std::string("--") + e.what());
  }
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double parse_number(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size())
    throw UsageError(what + " must be a number, got '" + text + "'");
  if (!std::isfinite(value) && errno != ERANGE) throw UsageError(what + " must be a finite number, got '" + text + "'");
  if (errno == ERANGE && std::abs(value) > 1)
    throw UsageError(what + " " + text + " is too large for double precision (beyond 1.8e308)");
  if (errno == ERANGE)
    throw UsageError(what + " " + text + " is too small for double precision (below 2.2e-308); give it in mesh units");
  return value;
}

std::int64_t parse_index(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
    throw UsageError(what + " must be a whole number, got '" + text + "'");
  if (value < 0) throw UsageError(what + " must be >= 0 (indices are 0-based), got " + text);
  return value;
}

std::vector<std::int64_t> parse_picks(const std::string& text) {
  std::vector<std::int64_t> picks;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    // Tolerate spaces around items ("12, 840, 77").
    const std::size_t first = item.find_first_not_of(' '), last = item.find_last_not_of(' ');
    item = first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    picks.push_back(parse_index(item, "--picks item"));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return picks;
}

/// --allow-partial (any command): intake keeps the readable part and reports what it skipped.
bool g_allow_partial = false;

/// Loads a mesh; a partial load is always reported on stderr, even with --quiet.
rs::Mesh load_mesh(const std::string& path, double* load_seconds) {
  const auto start = std::chrono::steady_clock::now();
  rs::IntakeOptions intake;
  intake.allow_partial = g_allow_partial;
  rs::Mesh mesh = rs::Mesh::load(path, intake);
  *load_seconds = seconds_since(start);
  if (mesh.report().partial())
    std::fprintf(stderr, "relief-snake: warning: partial load of %s: %s\n", path.c_str(),
                 mesh.report().summary().c_str());
  return mesh;
}

void check_vertex(const rs::Mesh& mesh, std::int64_t index, const std::string& what) {
  const std::size_t n = mesh.input_vertex_count();
  if (index < 0 || static_cast<std::size_t>(index) >= n)
    throw rs::Error(what + " " + std::to_string(index) + " is out of range: the mesh file has " + std::to_string(n) +
                    " vertices (indices are 0-based)");
  if (mesh.input_to_mesh(static_cast<std::size_t>(index)) < 0)
    throw rs::Error(what + " " + std::to_string(index) +
                    " is in no face of the mesh (unused or in a refused face); pick a vertex on the surface");
}


// --- commands ------------------------------------------------------------------

int run_info(const std::vector<std::string>& args) {
  if (args.size() != 1) throw UsageError("info takes exactly one argument: MESH");
  double load_seconds = 0;
  const rs::Mesh mesh = load_mesh(args[0], &load_seconds);
  const rs::MeshReport& r = mesh.report();
  std::cout << "mesh: " << args[0] << "\n"
            << "summary: " << r.summary() << "\n"
            << "input vertices: " << r.input_vertices << "\n"
            << "input faces: " << r.input_faces << "\n"
            << "vertices: " << mesh.n_vertices() << "\n"
            << "triangles: " << r.triangles << "\n"
            << "polygons triangulated: " << r.polygons_triangulated << "\n"
            << "duplicate vertices merged: " << r.duplicate_vertices_merged << "\n"
            << "unreferenced vertices: " << r.unreferenced_vertices << "\n"
            << "degenerate faces skipped: " << r.degenerate_faces << "\n"
            << "non-manifold faces refused: " << r.nonmanifold_faces << "\n"
            << "invalid faces skipped (--allow-partial): " << r.invalid_faces << "\n"
            << "invalid vertices ignored (--allow-partial): " << r.invalid_vertices << "\n"
            << "components: " << r.components << "\n"
            << "boundary edges: " << r.boundary_edges << "\n"
            << "average edge length: " << mesh.average_edge_length() << "\n"
            << "bounding box diagonal: " << mesh.bbox_diagonal() << "\n"
            << "load seconds: " << load_seconds << "\n";
  return 0;
}

int run_measure(const std::vector<std::string>& args) {
  if (args.size() != 3) throw UsageError("measure takes exactly three arguments: MESH I J");
  const std::int64_t i = parse_index(args[1], "I"), j = parse_index(args[2], "J");
  double load_seconds = 0;
  const rs::Mesh mesh = load_mesh(args[0], &load_seconds);
  const double d = rs::measure_distance(mesh, i, j);
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", d);
  std::cout << text << "\n";
  return 0;
}

struct SegmentArgs {
  std::string mesh_path, out_path;
  std::vector<std::int64_t> picks;
  std::vector<std::vector<std::int64_t>> groups;  ///< every --picks, in order (picks: the first)
  rs::Options options;
  bool have_picks = false, have_height = false, have_side = false, quiet = false;
};

SegmentArgs parse_segment(const std::vector<std::string>& args) {
  SegmentArgs a;
  std::vector<std::string> positional;
  for (std::size_t k = 0; k < args.size(); ++k) {
    std::string name = args[k], value;
    bool inline_value = false;
    if (name.rfind("--", 0) == 0) {
      const std::size_t eq = name.find('=');
      if (eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        inline_value = true;
      }
    }
    auto take_value = [&]() -> std::string {
      if (inline_value) return value;
      if (k + 1 >= args.size()) throw UsageError(name + " needs a value");
      return args[++k];
    };
    auto no_value = [&]() {
      if (inline_value) throw UsageError(name + " takes no value");
    };
    if (name == "--picks") {
      a.groups.push_back(parse_picks(take_value()));
      a.picks = a.groups.front();
      a.have_picks = true;
    } else if (name == "--step-height") {
      const std::string value = take_value();
      a.options.step_height = value == "auto" ? rs::kAuto : parse_number(value, "--step-height");
      if (value != "auto" && !(a.options.step_height > 0)) throw UsageError("--step-height must be > 0 or auto");
      a.have_height = true;
    } else if (name == "--w-int") {
      const std::string value = take_value();
      a.options.w_int = value == "auto" ? rs::kAuto : parse_number(value, "--w-int");
      if (value != "auto" && !(a.options.w_int > 0 && a.options.w_int <= 1))
        throw UsageError("--w-int must be in (0, 1] or auto");
    } else if (name == "--open") {
      no_value();
      a.options.closed = false;
    } else if (name == "--relief-side") {
      const std::string side = take_value();
      if (side == "left")
        a.options.relief_side = rs::ReliefSide::Left;
      else if (side == "right")
        a.options.relief_side = rs::ReliefSide::Right;
      else if (side == "auto")
        a.options.relief_side = rs::ReliefSide::Auto;
      else
        throw UsageError("--relief-side must be 'left', 'right' or 'auto', got '" + side + "'");
      a.have_side = true;
    } else if (name == "--max-iterations") {
      const std::int64_t n = parse_index(take_value(), "--max-iterations");
      if (n < 1 || n > 100000000) throw UsageError("--max-iterations must be between 1 and 100000000");
      a.options.max_iterations = static_cast<int>(n);
    } else if (name == "--option") {
      set_advanced_option(a.options, take_value());
    } else if (name == "--out" || name == "-o") {
      a.out_path = take_value();
      if (a.out_path.empty()) throw UsageError("--out needs a file name");
    } else if (name == "--quiet" || name == "-q") {
      no_value();
      a.quiet = true;
    } else if (name.size() > 1 && name[0] == '-') {
      throw UsageError("unknown option '" + name + "' for segment (see relief-snake --help)");
    } else {
      positional.push_back(name);
    }
  }
  if (positional.size() != 1)
    throw UsageError(positional.empty() ? "segment needs a MESH file" : "segment takes one MESH file, got " +
                                                                            std::to_string(positional.size()) +
                                                                            " arguments");
  a.mesh_path = positional[0];
  if (!a.have_picks) throw UsageError("segment needs --picks I,J,K,... (0-based vertex indices around the relief)");
  if (a.have_side && a.options.closed) throw UsageError("--relief-side only applies with --open");
  const std::size_t min_picks = a.options.closed ? 3 : 2;
  for (const auto& group : a.groups)
    if (group.size() < min_picks)
      throw UsageError(std::string("--picks needs at least ") + std::to_string(min_picks) + " vertices for " +
                     (a.options.closed ? "a closed" : "an open") + " contour");
  return a;
}

int run_segment(const std::vector<std::string>& args) {
  const SegmentArgs a = parse_segment(args);
  double load_seconds = 0;
  const rs::Mesh mesh = load_mesh(a.mesh_path, &load_seconds);
  for (const auto& group : a.groups)
    for (const std::int64_t p : group) check_vertex(mesh, p, "pick");
  if (!a.quiet)
    std::fprintf(stderr, "relief-snake: loaded %s in %.2f s: %s\n", a.mesh_path.c_str(), load_seconds,
                 mesh.report().summary().c_str());

  if (a.groups.size() > 1)
    return rs::cli::run_segment_groups(mesh, a.groups, a.options, a.mesh_path, a.out_path, load_seconds, a.quiet);

  // Progress: at phase changes and every 25 iterations.
  std::string last_phase;
  rs::ProgressCallback progress;
  if (!a.quiet) {
    progress = [&last_phase](const rs::Progress& p) {
      const bool new_phase = last_phase != p.phase;
      if (new_phase || p.iteration % 25 == 0) {
        std::fprintf(stderr, "relief-snake: %-10s iteration %5d, %5d snaxels\n", p.phase, p.iteration, p.snaxels);
        last_phase = p.phase;
      }
      return true;
    };
  }
  const auto start = std::chrono::steady_clock::now();
  const rs::Result result = rs::segment(mesh, a.picks, a.options, progress);
  const double segment_seconds = seconds_since(start);

  rs::ResultContext context;
  context.mesh_path = a.mesh_path;
  context.picks = a.picks;
  context.load_seconds = load_seconds;
  context.segment_seconds = segment_seconds;
  const json out = rs::to_json(result, a.options, mesh, context);
  const std::string text = out.dump(2) + "\n";
  if (a.out_path.empty()) {
    std::cout << text;
    std::cout.flush();
    if (!std::cout) throw rs::Error("could not write the result to stdout");
  } else {
    std::ofstream file(a.out_path, std::ios::binary);
    if (!file) throw rs::Error("cannot write '" + a.out_path + "'; check the directory exists and is writable");
    file << text;
    file.close();
    if (!file) throw rs::Error("writing '" + a.out_path + "' failed; check the free disk space");
  }
  if (!a.quiet) {
    std::fprintf(stderr, "relief-snake: %s in %.2f s, %zu contour points, %zu relief vertices%s%s\n",
                 rs::to_string(result.status), segment_seconds, result.polyline.size(), result.relief_vertices.size(),
                 a.out_path.empty() ? "" : "; wrote ", a.out_path.c_str());
  }
  if (!a.quiet && !result.message.empty()) std::fprintf(stderr, "relief-snake: %s\n", result.message.c_str());
  // 3: a result was written, but the engine does not vouch for it (doubtful, iteration cap).
  return result.status == rs::Status::Converged ? 0 : 3;
}

/// One line, whatever the message holds.
std::string one_line(std::string message) {
  for (char& c : message)
    if (c == '\n' || c == '\r') c = ' ';
  return message;
}

int fail(const std::string& message, int code) {
  std::cerr << "relief-snake: " << one_line(message) << std::endl;
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty()) {
      std::cerr << kUsage;
      return 2;
    }
    const std::string help = std::string(kUsage) + "\n" + rs::cli::kExtractUsage + "\n" + rs::cli::kDetectUsage + "\n" +
                             advanced_options_help();
    const std::string command = args[0];
    if (command == "--help" || command == "-h" || command == "help") {
      std::cout << help;
      return 0;
    }
    std::vector<std::string> rest;
    for (auto it = args.begin() + 1; it != args.end(); ++it) {
      if (*it == "--allow-partial") g_allow_partial = true;
      else rest.push_back(*it);
    }
    for (const std::string& arg : rest)
      if (arg == "--help") {
        std::cout << help;
        return 0;
      }
    if (command == "segment") return rs::cli::run_segment_with_extract(rest, run_segment);
    if (command == "extract") return rs::cli::run_extract(rest);
    if (command == "detect") {
      try {
        return rs::cli::run_detect(rest, load_mesh);
      } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
      }
    }
    if (command == "measure") return run_measure(rest);
    if (command == "info") return run_info(rest);
    throw UsageError("unknown command '" + command + "'; use segment, detect, measure, info or extract (see relief-snake --help)");
  } catch (const UsageError& e) {
    return fail(e.what(), 2);
  } catch (const rs::Error& e) {
    return fail(e.what(), 1);
  } catch (const std::bad_alloc&) {
    return fail("out of memory; try a smaller mesh or close other programs", 1);
  } catch (const std::exception& e) {
    return fail(std::string("unexpected error: ") + e.what(), 1);
  } catch (...) {
    return fail("unexpected error", 1);
  }
}
