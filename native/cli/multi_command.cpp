// relief-snake detect, and segment with several pick groups.
#include "multi_command.hpp"

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "relief_snake/detect.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/multi_json.hpp"
#include "relief_snake/multi_segment.hpp"
#include "relief_snake/option_table.hpp"

namespace relief_snake::cli {

const char* kDetectUsage =
    "detect: propose the reliefs of a region without picks (robust background fit, Otsu threshold,\n"
    "        components, each refined by the snake from its own outline; docs/result-format.md).\n"
    "  relief-snake detect MESH [--region-vertices FILE] [--min-area A] [--out FILE] [options]\n"
    "  --region-vertices FILE  0-based vertex indices (whitespace or comma separated, or a JSON list) of\n"
    "                          the region to search; default the whole mesh\n"
    "  --min-area A            smallest relief area kept, in mesh units squared (default (12 average\n"
    "                          edges)^2, about a disk 13 edges across)\n"
    "  --step-height H         refine every candidate with this h (default: each candidate's own height)\n"
    "  --background-degree D   degree of the background polynomial, 0..6, or auto (the default: the lowest\n"
    "                          of 2, 4, 6 that fits about as well as the best)\n"
    "  --no-refine             only the thresholded components (no snake): fast, rough outlines\n"
    "  --option NAME=VALUE     an advanced option of the snake (as for segment)\n"
    "  --out FILE              write the JSON document to FILE instead of stdout\n"
    "  --quiet                 no progress on stderr\n"
    "  exit codes: 0 written (every candidate converged, or none found), 3 written but some candidate is\n"
    "  doubtful or failed, 1 bad input, 2 usage error\n";

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double number(const std::string& text, const std::string& what) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(value) || errno == ERANGE)
    throw std::invalid_argument(what + " must be a finite number, got '" + text + "'");
  return value;
}

std::vector<std::int64_t> read_indices(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read '" + path + "'; check the path");
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string text = buffer.str();
  std::vector<std::int64_t> out;
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '[') {
    try {
      for (const auto& item : nlohmann::json::parse(text)) {
        if (!item.is_number_integer()) throw Error(path + ": expected a JSON list of whole numbers");
        out.push_back(item.get<std::int64_t>());
      }
    } catch (const nlohmann::json::exception& e) {
      throw Error(path + " is not a valid JSON list: " + e.what());
    }
  } else {
    for (char& c : text)
      if (c == ',') c = ' ';
    std::istringstream items(text);
    std::string item;
    while (items >> item) {
      char* end = nullptr;
      errno = 0;
      const long long v = std::strtoll(item.c_str(), &end, 10);
      if (end != item.c_str() + item.size() || errno == ERANGE)
        throw Error(path + ": '" + item + "' is not a vertex index; give 0-based whole numbers");
      out.push_back(v);
    }
  }
  if (out.empty()) throw Error(path + " holds no vertex index; give the region's 0-based vertex indices");
  for (const std::int64_t v : out)
    if (v < 0) throw Error(path + ": vertex index " + std::to_string(v) + " is negative (indices are 0-based)");
  return out;
}

}  // namespace

void write_document(const std::string& text, const std::string& path) {
  if (path.empty()) {
    std::cout << text;
    std::cout.flush();
    if (!std::cout) throw Error("could not write the result to stdout");
    return;
  }
  const std::string temporary = path + ".part";
  {
    std::ofstream file(temporary, std::ios::binary);
    if (!file) throw Error("cannot write '" + path + "'; check the directory exists and is writable");
    file << text;
    file.close();
    if (!file) {
      std::remove(temporary.c_str());
      throw Error("writing '" + path + "' failed; check the free disk space");
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    std::remove(temporary.c_str());
    throw Error("cannot replace '" + path + "'; check it is writable");
  }
}

int run_segment_groups(const Mesh& mesh, const std::vector<std::vector<std::int64_t>>& groups, const Options& options,
                       const std::string& mesh_path, const std::string& out_path, double load_seconds, bool quiet) {
  Segmenter segmenter(mesh);
  std::string last_phase;
  std::size_t last_group = groups.size();
  GroupProgressCallback progress;
  if (!quiet)
    progress = [&](std::size_t g, const Progress& p) {
      if (g != last_group || last_phase != p.phase || p.iteration % 25 == 0) {
        std::fprintf(stderr, "relief-snake: relief %zu/%zu %-10s iteration %5d, %5d snaxels\n", g + 1, groups.size(),
                     p.phase, p.iteration, p.snaxels);
        last_phase = p.phase, last_group = g;
      }
      return true;
    };
  const auto start = std::chrono::steady_clock::now();
  const MultiResult result = segment_many(segmenter, mesh, groups, options, progress);
  ResultContext context;
  context.mesh_path = mesh_path;
  context.load_seconds = load_seconds;
  context.segment_seconds = seconds_since(start);
  const nlohmann::json doc = multi_result_json(result, groups, options, mesh, context);
  write_document(doc.dump(2) + "\n", out_path);
  if (!quiet) {
    for (std::size_t g = 0; g < doc["reliefs"].size(); ++g) {
      const auto& r = doc["reliefs"][g];
      std::fprintf(stderr, "relief-snake: relief %zu: %s, %zu relief vertices%s%s\n", g + 1,
                   r["status"].get<std::string>().c_str(), r["relief_vertices"].size(),
                   r["message"].get<std::string>().empty() ? "" : ": ", r["message"].get<std::string>().c_str());
    }
    std::fprintf(stderr, "relief-snake: %zu reliefs in %.2f s, %zu overlapping pairs%s%s\n", groups.size(),
                 context.segment_seconds, result.overlaps.size(), out_path.empty() ? "" : "; wrote ", out_path.c_str());
  }
  return doc["status"] == "converged" ? 0 : 3;
}

int run_detect(const std::vector<std::string>& args, const MeshLoader& load) {
  DetectOptions options;
  std::string mesh_path, out_path, region_path;
  bool quiet = false;
  std::vector<std::string> positional;
  for (std::size_t k = 0; k < args.size(); ++k) {
    std::string name = args[k], value;
    bool inline_value = false;
    if (name.rfind("--", 0) == 0 && name.find('=') != std::string::npos) {
      value = name.substr(name.find('=') + 1);
      name = name.substr(0, name.find('='));
      inline_value = true;
    }
    auto take = [&]() -> std::string {
      if (inline_value) return value;
      if (k + 1 >= args.size()) throw std::invalid_argument(name + " needs a value");
      return args[++k];
    };
    if (name == "--region-vertices") {
      region_path = take();
    } else if (name == "--min-area") {
      options.min_area = number(take(), "--min-area");
      if (!(options.min_area > 0)) throw std::invalid_argument("--min-area must be > 0 (mesh units squared)");
    } else if (name == "--step-height") {
      const std::string v = take();
      options.segment.step_height = v == "auto" ? kAuto : number(v, "--step-height");
      if (v != "auto" && !(options.segment.step_height > 0)) throw std::invalid_argument("--step-height must be > 0 or auto");
    } else if (name == "--background-degree") {
      const std::string v = take();
      if (v == "auto") {
        options.background_degree = kAutoDegree;
      } else {
        const double d = number(v, "--background-degree");
        if (d != std::floor(d) || d < 0 || d > 6) throw std::invalid_argument("--background-degree must be 0..6 or auto");
        options.background_degree = static_cast<int>(d);
      }
    } else if (name == "--no-refine") {
      if (inline_value) throw std::invalid_argument("--no-refine takes no value");
      options.refine = false;
    } else if (name == "--option") {
      const std::string assignment = take();
      const std::size_t eq = assignment.find('=');
      if (eq == std::string::npos || eq == 0)
        throw std::invalid_argument("--option needs NAME=VALUE, got '" + assignment + "'; valid names: " +
                                    advanced_option_names());
      try {
        set_advanced_option(&options.segment, assignment.substr(0, eq), assignment.substr(eq + 1));
      } catch (const Error& e) {
        throw std::invalid_argument(std::string("--") + e.what());
      }
    } else if (name == "--out" || name == "-o") {
      out_path = take();
      if (out_path.empty()) throw std::invalid_argument("--out needs a file name");
    } else if (name == "--quiet" || name == "-q") {
      quiet = true;
    } else if (name.size() > 1 && name[0] == '-') {
      throw std::invalid_argument("unknown option '" + name + "' for detect (see relief-snake --help)");
    } else {
      positional.push_back(name);
    }
  }
  if (positional.size() != 1)
    throw std::invalid_argument(positional.empty() ? "detect needs a MESH file"
                                                   : "detect takes one MESH file, got " +
                                                         std::to_string(positional.size()) + " arguments");
  mesh_path = positional[0];
  const std::vector<std::int64_t> region = region_path.empty() ? std::vector<std::int64_t>{} : read_indices(region_path);
  double load_seconds = 0;
  const Mesh mesh = load(mesh_path, &load_seconds);
  for (const std::int64_t v : region)  // bad input is one line, before any progress
    if (static_cast<std::size_t>(v) >= mesh.input_vertex_count())
      throw Error(region_path + ": region vertex " + std::to_string(v) + " is out of range: the mesh file has " +
                  std::to_string(mesh.input_vertex_count()) + " vertices (indices are 0-based)");
  if (!quiet)
    std::fprintf(stderr, "relief-snake: loaded %s in %.2f s: %s\n", mesh_path.c_str(), load_seconds,
                 mesh.report().summary().c_str());
  Segmenter segmenter(mesh);
  std::size_t last = static_cast<std::size_t>(-1);
  GroupProgressCallback progress;
  if (!quiet)
    progress = [&](std::size_t c, const Progress& p) {
      const std::string phase = p.phase ? p.phase : "";
      if (phase == "candidates")
        std::fprintf(stderr, "relief-snake: %d candidates above the background\n", p.iteration);
      else if (phase != "background" && c != last)
        std::fprintf(stderr, "relief-snake: refining candidate %zu\n", c + 1), last = c;
      return true;
    };
  const DetectResult result = detect(segmenter, mesh, region, options, progress);
  ResultContext context;
  context.mesh_path = mesh_path;
  context.load_seconds = load_seconds;
  const nlohmann::json doc = detect_json(result, options, mesh, context);
  write_document(doc.dump(2) + "\n", out_path);
  bool all_converged = true;
  for (const auto& c : doc["candidates"]) all_converged = all_converged && c["status"] == "converged";
  if (!quiet) {
    for (std::size_t c = 0; c < doc["candidates"].size(); ++c) {
      const auto& d = doc["candidates"][c];
      std::fprintf(stderr, "relief-snake: candidate %zu: %s, area %.4g, h %.4g, score %.2f\n", c + 1,
                   d["status"].get<std::string>().c_str(), d["detection"]["area"].get<double>(),
                   d["step_height"]["used"].get<double>(), d["detection"]["score"].get<double>());
    }
    std::fprintf(stderr, "relief-snake: %zu candidates in %.2f s (threshold %.4g, noise sigma %.3g)%s%s\n",
                 result.candidates.size(), result.seconds, result.background.threshold, result.background.sigma,
                 out_path.empty() ? "" : "; wrote ", out_path.c_str());
  }
  return (!options.refine || all_converged) ? 0 : 3;
}

}  // namespace relief_snake::cli
