// relief-snake extract: base surface, relief mesh and height map from a segmentation result.
#include "extract_command.hpp"
#include "parse_number.hpp"

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "relief_snake/error.hpp"
#include "relief_snake/extract.hpp"
#include "relief_snake/mesh.hpp"

namespace relief_snake::cli {

const char* kExtractUsage =
    "extract: the relief's base surface, height map and meshes from a segmentation result.\n"
    "  relief-snake extract MESH RESULT.json --out DIR [--pixel-size S] [--flatten auto|plane|conformal]\n"
    "  writes DIR/background.ply (the scan with the relief on its base), DIR/relief.ply (the relief,\n"
    "  per-vertex float 'height', 'u', 'v'), DIR/height.exr (32-bit float), DIR/height.png (16-bit) and\n"
    "  DIR/height.json (pixel size, frame, height range, PNG scale); prints one summary line.\n"
    "  --pixel-size S         height-map pixel size in mesh units (default half the average edge)\n"
    "  --flatten M            auto (default): plane for gentle backgrounds, else conformal\n"
    "  --step-height H        h, if RESULT.json does not record it (it sets the background ring's width)\n"
    "  --timings              also print each stage's time (reading, loading, solving, flattening, writing)\n"
    "  segment ... --extract DIR [--pixel-size S] [--flatten M] segments, then extracts into DIR\n"
    "  (the result goes to DIR/result.json unless --out is given).\n";

namespace {

struct ExtractUsage : std::runtime_error {
  explicit ExtractUsage(const std::string& message) : std::runtime_error(message) {}
};

double positive_number(const std::string& text, const std::string& what) {
  const double value = parse_number<ExtractUsage>(text, what);
  if (!(value > 0)) throw ExtractUsage(what + " must be a positive number, got '" + text + "'");
  return value;
}

struct ExtractArgs {
  std::string mesh_path, result_path, out_dir;
  double pixel_size = 0, step_height = 0;
  Flattening flattening = Flattening::Auto;
  bool quiet = false;
  bool timings = false;
};

/// Reads --pixel-size, --flatten, --step-height, --out, --quiet, --timings; the rest are positional.
ExtractArgs parse(const std::vector<std::string>& args, std::vector<std::string>* positional) {
  ExtractArgs a;
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
      if (k + 1 >= args.size()) throw ExtractUsage(name + " needs a value");
      return args[++k];
    };
    if (name == "--out" || name == "-o") {
      a.out_dir = take();
      if (a.out_dir.empty()) throw ExtractUsage("--out needs a directory");
    } else if (name == "--pixel-size") {
      a.pixel_size = positive_number(take(), "--pixel-size");
    } else if (name == "--step-height") {
      a.step_height = positive_number(take(), "--step-height");
    } else if (name == "--flatten") {
      const std::string m = take();
      try {
        a.flattening = parse_flattening(m);
      } catch (const Error&) {
        throw ExtractUsage("--flatten must be auto, plane or conformal, got '" + m + "'");
      }
    } else if (name == "--quiet" || name == "-q") {
      a.quiet = true;
    } else if (name == "--timings" && !inline_value) {
      a.timings = true;
    } else if (name.size() > 1 && name[0] == '-') {
      throw ExtractUsage("unknown option '" + name + "' for extract (see relief-snake --help)");
    } else {
      positional->push_back(name);
    }
  }
  return a;
}

int usage_failure(const std::string& message) {
  std::cerr << "relief-snake: " << message << std::endl;
  return 2;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int extract_files(const ExtractArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  nlohmann::json result;
  {
    std::ifstream in(a.result_path, std::ios::binary);
    if (!in) throw Error("cannot open '" + a.result_path + "': no such file or not readable; check the path");
    try {
      result = nlohmann::json::parse(in);
    } catch (const std::exception&) {
      throw Error("'" + a.result_path + "' is not JSON; give the result file written by 'relief-snake segment'");
    }
  }
  if (!result.is_object() || !result.contains("relief_vertices") || !result["relief_vertices"].is_array())
    throw Error("'" + a.result_path + "' has no relief_vertices list; give the result file written by 'relief-snake segment'");
  std::vector<std::int64_t> relief;
  relief.reserve(result["relief_vertices"].size());
  for (const auto& item : result["relief_vertices"]) {
    if (!item.is_number_integer())
      throw Error("'" + a.result_path + "': relief_vertices must hold whole vertex indices");
    relief.push_back(item.get<std::int64_t>());
  }
  std::int64_t expected = -1;
  if (result.contains("mesh") && result["mesh"].is_object() && result["mesh"].contains("input_vertices") &&
      result["mesh"]["input_vertices"].is_number_integer())
    expected = result["mesh"]["input_vertices"].get<std::int64_t>();
  double h = a.step_height;
  if (!(h > 0) && result.contains("parameters") && result["parameters"].is_object() &&
      result["parameters"].contains("step_height") && result["parameters"]["step_height"].is_number())
    h = result["parameters"]["step_height"].get<double>();
  if (!(h > 0))
    throw Error("'" + a.result_path + "' does not record the step height; give it with --step-height H");

  const double read_seconds = seconds_since(start);
  const auto load_start = std::chrono::steady_clock::now();
  const Mesh mesh = Mesh::load(a.mesh_path);
  const double load_seconds = seconds_since(load_start);
  std::vector<std::string> notes;
  if (expected < 0)
    notes.push_back("the result does not record its mesh's vertex count; its indices were checked against the mesh only");
  const std::vector<char> region = region_from_input_indices(mesh, relief, expected, &notes);
  ExtractOptions options;
  options.height_map.pixel_size = a.pixel_size;
  options.height_map.flattening = a.flattening;
  ExtractResult x = extract(mesh, region, h, options);
  x.notes.insert(x.notes.begin(), notes.begin(), notes.end());
  if (mesh.report().duplicate_vertices_merged || mesh.report().unreferenced_vertices)
    x.notes.push_back("intake merged or dropped vertices: background.ply holds the mesh's " +
                      std::to_string(mesh.n_vertices()) + " vertices, not the file's " +
                      std::to_string(mesh.input_vertex_count()));
  const auto write_start = std::chrono::steady_clock::now();
  write_extraction(mesh, x, a.out_dir);
  const double write_seconds = seconds_since(write_start);
  const double seconds = seconds_since(start);
  if (!a.quiet)
    for (const std::string& note : x.notes) std::fprintf(stderr, "relief-snake: note: %s\n", note.c_str());
  std::printf("relief-snake: %s; wrote %s in %.2f s total\n", x.summary().c_str(), a.out_dir.c_str(), seconds);
  if (a.timings)
    std::printf("relief-snake: timings: read result %.3f s, load mesh %.3f s, %s, write %.3f s\n", read_seconds,
                load_seconds, x.timings_text().c_str(), write_seconds);
  std::fflush(stdout);
  return 0;
}

}  // namespace

int run_extract(const std::vector<std::string>& args) {
  ExtractArgs a;
  try {
    std::vector<std::string> positional;
    a = parse(args, &positional);
    if (positional.size() != 2)
      throw ExtractUsage("extract takes MESH and RESULT.json, got " + std::to_string(positional.size()) + " arguments");
    if (a.out_dir.empty()) throw ExtractUsage("extract needs --out DIR (where the five files go)");
    a.mesh_path = positional[0];
    a.result_path = positional[1];
  } catch (const ExtractUsage& e) {
    return usage_failure(e.what());
  }
  return extract_files(a);
}

int run_segment_with_extract(const std::vector<std::string>& args,
                             const std::function<int(const std::vector<std::string>&)>& segment) {
  std::vector<std::string> segment_args;
  std::string dir, out, mesh_path;
  ExtractArgs a;
  try {
    std::vector<std::string> extract_args;
    for (std::size_t k = 0; k < args.size(); ++k) {
      const std::string& arg = args[k];
      const std::string name = arg.substr(0, arg.find('='));
      const bool inline_value = arg.find('=') != std::string::npos && arg.rfind("--", 0) == 0;
      auto take = [&]() -> std::string {
        if (inline_value) return arg.substr(arg.find('=') + 1);
        if (k + 1 >= args.size()) throw ExtractUsage(name + " needs a value");
        return args[++k];
      };
      if (name == "--extract") {
        dir = take();
        if (dir.empty()) throw ExtractUsage("--extract needs a directory");
      } else if (name == "--pixel-size" || name == "--flatten") {
        extract_args.push_back(name);
        extract_args.push_back(take());
      } else {
        segment_args.push_back(arg);
        if ((name == "--out" || name == "-o")) {
          out = inline_value ? arg.substr(arg.find('=') + 1) : (k + 1 < args.size() ? args[k + 1] : "");
        }
      }
    }
    std::vector<std::string> positional;
    a = parse(extract_args, &positional);
    if (dir.empty()) {
      if (!extract_args.empty()) throw ExtractUsage("--pixel-size and --flatten need --extract DIR");
      return segment(segment_args);
    }
    int pick_groups = 0;
    for (const std::string& arg : segment_args) pick_groups += arg == "--picks" || arg.rfind("--picks=", 0) == 0;
    if (pick_groups > 1)
      throw ExtractUsage("--extract takes one relief: give one --picks (extract the others with relief-snake "
                         "extract MESH RESULT.json, one result each)");
    // The mesh: segment's one positional argument (options with values are skipped).
    for (std::size_t k = 0; k < segment_args.size(); ++k) {
      const std::string& arg = segment_args[k];
      if (arg.rfind("-", 0) == 0) {
        const bool flag = arg == "--open" || arg == "--quiet" || arg == "-q" || arg.find('=') != std::string::npos;
        if (!flag) ++k;
        continue;
      }
      mesh_path = arg;
    }
  } catch (const ExtractUsage& e) {
    return usage_failure(e.what());
  }
  if (out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw Error("cannot create the output directory '" + dir + "': " + ec.message());
    out = (std::filesystem::path(dir) / "result.json").string();
    segment_args.push_back("--out");
    segment_args.push_back(out);
  }
  const int code = segment(segment_args);
  if (code != 0) return code;
  a.mesh_path = mesh_path;
  a.result_path = out;
  a.out_dir = dir;
  return extract_files(a);
}

}  // namespace relief_snake::cli
