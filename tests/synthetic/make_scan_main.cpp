// make-scan: writes a synthetic scan (PLY or OBJ) and its ground truth (JSON), or scores a
// segmentation result against a truth file. Run `make-scan --help`.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "relief_snake/error.hpp"
#include "relief_snake/mesh.hpp"
#include "plate_scans.hpp"
#include "synthetic.hpp"
#include "hole_scans.hpp"

namespace rs = relief_snake;
namespace syn = relief_snake::synthetic;

namespace {

const char* kUsage =
    "usage:\n"
    "  make-scan [options] --out PREFIX        writes PREFIX.ply (or .obj) and PREFIX.truth.json\n"
    "  make-scan --random SEED --out PREFIX    one scan of the random family: PREFIX.ply, PREFIX.json (truth),\n"
    "                                          PREFIX.background.npy (per vertex base, normal, heights)\n"
    "  make-scan tube [--radius R] [--vase A] [--h H (< 0: engraved)] [--half-width W] [--wave A] [--waves N]\n"
    "            [--step sharp|blended] [--noise S] [--triangles N] [--seed K] [--picks N] [--distance D] --out PREFIX\n"
    "                                          a band right round a cylinder or vase: truth boundary = both band edges,\n"
    "                                          picks and band_picks = one pick ring on each side\n"
    "  make-scan score TRUTH.json RESULT.json [--mesh MESH]\n"
    "                                          prints {iou, mean/p95/max distances both ways, in average edges};\n"
    "                                          with --mesh also iou_area (vertex-area weighted) and the one-edge\n"
    "                                          IoU floors (truth against truth grown by one average edge)\n"
    "options (defaults in brackets):\n"
    "  --shape duck|disk|rectangle|slots|open|gear|c|ellipse|rounded-box|letter|band|ring|holed-letter [duck]\n"
    "  --letter O|D|A|B (holed-letter)   --stroke-width W [7]   --ring-radius R [13]   --ring-half-thickness T [4]\n"
    "  --background plane|cylinder|sphere|saddle|vase|wavy [plane]   --texture none|striations|dots [none]\n"
    "  --triangles N [100000]   --h H [1]   --seed K [1]   --radius R [40]   --width W [80]   --height H [56]\n"
    "  --step sharp|blended [sharp]   --blend-width B [0.5, in h]   --detail A [0, fraction of h]   --drop\n"
    "  --noise S [0, sigma as a fraction of h]   --jitter J [0.3]\n"
    "  --slots W1,W2,.. [3,5,8,12, mouth widths in average edges]   --slot-depth D [5, in h]\n"
    "  --start near|far|zigzag [near]   --picks N [8]   --distance D [3, in h]   --far-distance D [auto, in h]\n"
    "  --reverse (reverse the pick order)   --format ply|obj [ply]\n"
    "RESULT.json needs \"polyline\" (or \"contour\") as [[x,y,z],...] and \"relief_vertices\"; \"closed\" is optional.\n";

std::vector<double> parse_list(const std::string& text) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::stod(item));
  return out;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw rs::Error("cannot read " + path + ": check the path");
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw rs::Error(path + " is not valid JSON: " + e.what());
  }
}

std::vector<rs::Vec3> points_of(const nlohmann::json& list) {
  std::vector<rs::Vec3> out;
  for (const auto& p : list) {
    if (!p.is_array() || p.size() != 3) throw rs::Error("expected a list of [x, y, z] points");
    out.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  }
  return out;
}

int run_score(const std::string& truth_path, const std::string& result_path, const std::string& mesh_path) {
  const nlohmann::json truth = read_json(truth_path), result = read_json(result_path);
  std::vector<syn::Polyline> boundary;
  const auto& b = truth.at("boundary");
  // boundary: a list of polylines (or, accepted too, one polyline as a list of points)
  const bool nested = !b.empty() && b[0].is_array() && !b[0].empty() && b[0][0].is_array();
  if (nested) {
    for (std::size_t i = 0; i < b.size(); ++i) {
      syn::Polyline p;
      p.points = points_of(b[i]);
      p.closed = truth.contains("boundary_closed") ? truth["boundary_closed"][i].get<bool>() : !truth.value("open", false);
      boundary.push_back(std::move(p));
    }
  } else {
    boundary.push_back({points_of(b), !truth.value("open", false)});
  }
  syn::Polyline contour;
  if (result.contains("polyline")) contour.points = points_of(result["polyline"]);
  else if (result.contains("contour")) contour.points = points_of(result["contour"]);
  else throw rs::Error(result_path + " has no \"polyline\" (list of [x, y, z]): pass a segmentation result");
  contour.closed = result.value("closed", !truth.value("open", false));
  const std::vector<std::int64_t> relief = result.value("relief_vertices", std::vector<std::int64_t>{});
  const syn::Score s = syn::score(contour, relief, boundary, truth.at("relief_vertices").get<std::vector<std::int64_t>>(),
                                  truth.at("average_edge").get<double>());
  nlohmann::json out = {{"iou", s.iou},
                        {"result_vertices", s.result_vertices},
                        {"truth_vertices", s.truth_vertices},
                        {"common_vertices", s.common_vertices},
                        {"mean_to_truth", s.mean_to_truth},
                        {"p95_to_truth", s.p95_to_truth},
                        {"max_to_truth", s.max_to_truth},
                        {"mean_from_truth", s.mean_from_truth},
                        {"p95_from_truth", s.p95_from_truth},
                        {"max_from_truth", s.max_from_truth},
                        {"units", "average edges"}};
  if (!mesh_path.empty()) {
    // Vertex-area weighted IoU, and the one-edge floors: the truth region against itself grown by
    // every vertex within one average edge of the true boundary.
    const rs::Mesh mesh = rs::Mesh::load(mesh_path);
    const std::size_t n = mesh.input_vertex_count();
    std::vector<char> in_truth(n, 0), in_result(n, 0);
    for (std::int64_t v : truth.at("relief_vertices").get<std::vector<std::int64_t>>())
      if (v >= 0 && static_cast<std::size_t>(v) < n) in_truth[v] = 1;
    for (std::int64_t v : relief)
      if (v >= 0 && static_cast<std::size_t>(v) < n) in_result[v] = 1;
    const syn::PolylineDistance to_boundary(boundary);
    const double edge = truth.at("average_edge").get<double>();
    double common = 0, uni = 0, truth_n = 0, truth_a = 0, grown_n = 0, grown_a = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int m = mesh.input_to_mesh(i);
      if (m < 0) continue;
      const double a = mesh.vertex_area(m);
      common += (in_truth[i] && in_result[i]) ? a : 0;
      uni += (in_truth[i] || in_result[i]) ? a : 0;
      const bool grown = in_truth[i] || to_boundary.within(mesh.to_file(mesh.position(m)), edge);  // the truth is in the file's coordinates
      truth_n += in_truth[i], truth_a += in_truth[i] ? a : 0;
      grown_n += grown, grown_a += grown ? a : 0;
    }
    out["iou_area"] = uni > 0 ? common / uni : 1.0;
    out["iou_floor_vertices"] = grown_n > 0 ? truth_n / grown_n : 1.0;
    out["iou_floor_area"] = grown_a > 0 ? truth_a / grown_a : 1.0;
  }
  std::cout << out.dump(2) << std::endl;
  return 0;
}

int run_random(std::uint64_t seed, const std::string& out) {
  const auto t0 = std::chrono::steady_clock::now();
  const syn::RandomScan random = syn::generate_random(seed);
  const std::string mesh_path = out + ".ply", truth_path = out + ".json", background_path = out + ".background.npy";
  // The truth is written last, each file under a temporary name first: a PREFIX.json means a complete scan.
  syn::write_ply(random.scan, mesh_path + ".tmp");
  if (std::rename((mesh_path + ".tmp").c_str(), mesh_path.c_str()) != 0)
    throw rs::Error("cannot rename " + mesh_path + ".tmp: check the folder is writable");
  const std::size_t slash = background_path.find_last_of('/');
  syn::write_background_npy(random.scan, background_path);
  syn::write_json(syn::random_truth_json(random, slash == std::string::npos ? background_path
                                                                              : background_path.substr(slash + 1)),
                  truth_path);
  const nlohmann::json summary = {{"mesh", mesh_path},
                                  {"truth", truth_path},
                                  {"background", background_path},
                                  {"triangles", random.scan.n_faces()},
                                  {"average_edge", random.scan.average_edge},
                                  {"h", random.scan.h},
                                  {"attempts", random.attempts},
                                  {"axes", random.draw.axes},
                                  {"total_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  std::cout << summary.dump() << std::endl;
  return 0;
}

int run(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::cout << kUsage << syn::kPlateUsage;
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "score") {
    if (args.size() == 5 && args[3] == "--mesh") return run_score(args[1], args[2], args[4]);
    if (args.size() != 3) throw rs::Error("score needs two files: make-scan score TRUTH.json RESULT.json [--mesh MESH]");
    return run_score(args[1], args[2], "");
  }
  if (args[0] == "tube") return syn::tube_command(std::vector<std::string>(args.begin() + 1, args.end()));
  if (args[0] == "--plate") return syn::run_plate_command(args);
  if (args[0] == "--random") {
    if (args.size() != 4 || args[2] != "--out")
      throw rs::Error("--random needs a seed and an output prefix: make-scan --random SEED --out PREFIX");
    std::uint64_t seed = 0;
    try {
      std::size_t used = 0;
      seed = std::stoull(args[1], &used);
      if (used != args[1].size()) throw std::invalid_argument("seed");
    } catch (const std::logic_error&) {
      throw rs::Error("bad seed '" + args[1] + "': give a whole number >= 0");
    }
    return run_random(seed, args[3]);
  }
  syn::ScanSpec spec;
  syn::PickSpec picks;
  std::string out, format = "ply";
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) throw rs::Error(a + " needs a value (see make-scan --help)");
      return args[++i];
    };
    try {
      if (a == "--shape") spec.shape = syn::parse_shape(value());
      else if (a == "--background") spec.background = syn::parse_background(value());
      else if (a == "--texture") spec.texture = syn::parse_texture(value());
      else if (a == "--triangles") spec.triangles = std::stoull(value());
      else if (a == "--step") spec.step = syn::parse_step(value());
      else if (a == "--blend-width") spec.blend_width = std::stod(value());
      else if (a == "--detail") spec.detail = std::stod(value());
      else if (a == "--drop") spec.drop = true;
      else if (a == "--noise") spec.noise = std::stod(value());
      else if (a == "--jitter") spec.jitter = std::stod(value());
      else if (a == "--h") spec.h = std::stod(value());
      else if (a == "--seed") spec.seed = std::stoull(value());
      else if (a == "--radius") spec.radius = std::stod(value());
      else if (a == "--width") spec.width = std::stod(value());
      else if (a == "--height") spec.height = std::stod(value());
      else if (a == "--slots") spec.slot_widths = parse_list(value());
      else if (a == "--slot-depth") spec.slot_depth = std::stod(value());
      else if (a == "--start") picks.start = syn::parse_start(value());
      else if (a == "--picks") picks.count = std::stoi(value());
      else if (a == "--distance") picks.distance = std::stod(value());
      else if (a == "--far-distance") picks.far_distance = std::stod(value());
      else if (a == "--reverse") picks.reverse = true;
      else if (a == "--format") format = value();
      else if (a == "--letter") spec.letter = value().at(0);
      else if (a == "--stroke-width") spec.stroke_width = std::stod(value());
      else if (a == "--ring-radius") spec.c_radius = std::stod(value());
      else if (a == "--ring-half-thickness") spec.c_half_thickness = std::stod(value());
      else if (a == "--out") out = value();
      else throw rs::Error("unknown option " + a + " (see make-scan --help)");
    } catch (const std::logic_error& e) {  // std::stod and friends
      throw rs::Error("bad value for " + a + ": give a number (see make-scan --help)");
    }
  }
  if (out.empty()) throw rs::Error("--out PREFIX is required (writes PREFIX.ply and PREFIX.truth.json)");
  if (format != "ply" && format != "obj") throw rs::Error("--format must be ply or obj");

  const auto t0 = std::chrono::steady_clock::now();
  const syn::Scan scan = syn::generate(spec);
  const auto t1 = std::chrono::steady_clock::now();
  const syn::Picks p = scan.picks(picks);
  const std::string mesh_path = out + "." + format, truth_path = out + ".truth.json";
  if (format == "ply") syn::write_ply(scan, mesh_path);
  else syn::write_obj(scan, mesh_path);
  nlohmann::json truth = syn::truth_json(scan, p);
  syn::add_hole_truth(scan, &truth);  // "holes": the hole boundaries (issue 13)
  syn::write_json(truth, truth_path);
  const auto t2 = std::chrono::steady_clock::now();
  nlohmann::json summary = {{"mesh", mesh_path},
                            {"truth", truth_path},
                            {"triangles", scan.n_faces()},
                            {"vertices", scan.n_vertices()},
                            {"average_edge", scan.average_edge},
                            {"h", scan.h},
                            {"relief_fraction", scan.relief_fraction()},
                            {"picks", p.vertices.size()},
                            {"generate_seconds", std::chrono::duration<double>(t1 - t0).count()},
                            {"total_seconds", std::chrono::duration<double>(t2 - t0).count()}};
  std::cout << summary.dump() << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "make-scan: " << e.what() << std::endl;
    return 1;
  }
}
