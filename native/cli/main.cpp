// relief-snake: command-line front end of the engine.
//
//   relief-snake segment MESH --picks I,J,K,... --step-height H [options]   -> JSON result
//   relief-snake measure MESH I J                                          -> distance
//   relief-snake info MESH                                                 -> mesh report
//   relief-snake batch MANIFEST.json --out DIR [options]                    -> many scans (batch/)
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

#include "batch_command.hpp"
#include "extract_command.hpp"
#include "parse_number.hpp"
#include "multi_command.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/input_checks.hpp"
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
    "  relief-snake batch MANIFEST.json --out DIR [options]\n"
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
    "  --holes auto|off       closed contours: find the relief's inner holes (background islands) and\n"
    "                         segment each (default auto; islands under min_hole_area h^2 are ignored)\n"
    "  --hole-picks I,J,K,... one hole's picked vertices on its floor, in order round it (repeatable,\n"
    "                         one per hole); given hole picks replace the automatic search\n"
    "  --band-picks I,J,K,... a band right round the surface (a frieze): --picks is the ring on one side,\n"
    "                         this the ring on the other; the relief lies between the two contours\n"
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
  return rs::cli::parse_number<UsageError>(text, what);
}

std::int64_t parse_index(const std::string& text, const std::string& what) {
  return rs::cli::parse_index<UsageError>(text, what);
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

/// The engine's check of what the user typed (input_checks.hpp), its Error as a usage error.
template <class Check>
auto usage_checked(const Check& check) {
  try {
    return check();
  } catch (const rs::Error& e) {
    throw UsageError(e.what());
  }
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
            << "local origin: " << mesh.origin().x() << " " << mesh.origin().y() << " " << mesh.origin().z()
            << " (subtracted inside the engine; results are in the file's coordinates)\n"
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
      const std::string typed = take_value();
      a.options.step_height = typed == "auto" ? rs::kAuto : usage_checked([&] {
        return rs::checked_step_height(parse_number(typed, "--step-height"), "--step-height");
      });
      a.have_height = true;
    } else if (name == "--w-int") {
      const std::string typed = take_value();
      a.options.w_int = typed == "auto" ? rs::kAuto : usage_checked([&] {
        return rs::checked_w_int(parse_number(typed, "--w-int"), "--w-int");
      });
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
    } else if (name == "--holes") {
      const std::string mode = take_value();
      if (mode == "auto") a.options.holes = rs::HoleMode::Auto;
      else if (mode == "off") a.options.holes = rs::HoleMode::Off;
      else throw UsageError("--holes must be 'auto' or 'off', got '" + mode + "'");
    } else if (name == "--hole-picks") {
      a.options.hole_picks.push_back(parse_picks(take_value()));
      if (a.options.hole_picks.back().size() < 3) throw UsageError("--hole-picks needs at least 3 vertices per hole");
    } else if (name == "--band-picks") {
      a.options.band_picks = parse_picks(take_value());
      if (a.options.band_picks.size() < 3) throw UsageError("--band-picks needs at least 3 vertices round the surface");
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
  for (const auto& group : a.groups)
    usage_checked([&] {
      rs::check_pick_count(group.size(), a.options.closed);
      return 0;
    });
  return a;
}

int run_segment(const std::vector<std::string>& args) {
  const SegmentArgs a = parse_segment(args);
  double load_seconds = 0;
  const rs::Mesh mesh = load_mesh(a.mesh_path, &load_seconds);
  for (const auto& group : a.groups)
    for (const std::int64_t p : group) rs::checked_input_vertex(mesh, p, "pick");
  for (const auto& hole : a.options.hole_picks)
    for (const std::int64_t p : hole) rs::checked_input_vertex(mesh, p, "hole pick");
  for (const std::int64_t p : a.options.band_picks) rs::checked_input_vertex(mesh, p, "band pick");
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
  if (!a.quiet && result.step_height_measured > 0) {
    // The step the scan shows at the result's edge, beside the h the snake ran with.
    const double used = result.parameters.step_height, measured = result.step_height_measured;
    if (!(a.options.step_height > 0))
      std::fprintf(stderr, "relief-snake: step height estimated: %.4g at the contour's edge, segmented with h = %.4g "
                   "(confidence %.2f)\n", measured, used, result.step_height_confidence);
    else if (measured > 1.33 * used || measured < 0.75 * used)
      std::fprintf(stderr, "relief-snake: the step at the contour's edge measures %.4g, against h = %.4g typed\n",
                   measured, used);
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
    const std::string help = std::string(kUsage) + "\n" + rs::cli::kExtractUsage + "\n" + rs::cli::kDetectUsage + "\n" + rs::cli::kBatchUsage + "\n" +
                             advanced_options_help();
    const std::string command = args[0];
    if (command == "--help" || command == "-h" || command == "help") {
      std::cout << help;
      return 0;
    }
    // batch: the runner parses its own arguments (--help included) and runs this executable per entry.
    if (command == "batch") return rs::cli::run_batch(std::vector<std::string>(args.begin() + 1, args.end()));
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
    throw UsageError("unknown command '" + command + "'; use segment, detect, measure, info, extract or batch (see relief-snake --help)");
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
