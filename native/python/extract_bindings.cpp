// relief_snake_core.extract(): relief extraction for Python (Blender add-on, scripts).
// Inputs are copied into engine arrays with the GIL held; the extraction runs without it.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "relief_snake/error.hpp"
#include "relief_snake/extract.hpp"
#include "relief_snake/mesh.hpp"

namespace py = pybind11;

namespace relief_snake {
namespace {

/// Numbers from a buffer (array.array, memoryview, numpy, Blender foreach_get) or a
/// (possibly nested) sequence, flattened in C order.
template <class T>
std::vector<T> flat_numbers(py::handle obj, const char* what) {
  std::vector<T> out;
  if (py::isinstance<py::buffer>(obj) && !py::isinstance<py::str>(obj) && !py::isinstance<py::bytes>(obj)) {
    const py::buffer_info info = py::reinterpret_borrow<py::buffer>(obj).request();
    std::string format = info.format;
    if (!format.empty() && std::strchr("@=<", format[0])) format.erase(0, 1);
    if (format.size() != 1 || info.ndim < 1 || info.ndim > 2)
      throw Error(std::string(what) + ": give a flat or n by 3 array of plain numbers");
    const py::ssize_t rows = info.shape[0], cols = info.ndim == 2 ? info.shape[1] : 1;
    out.reserve(static_cast<std::size_t>(rows * cols));
    for (py::ssize_t r = 0; r < rows; ++r)
      for (py::ssize_t c = 0; c < cols; ++c) {
        const char* p = static_cast<const char*>(info.ptr) + r * info.strides[0] + (info.ndim == 2 ? c * info.strides[1] : 0);
        auto read = [&](auto sample) {
          decltype(sample) value;
          std::memcpy(&value, p, sizeof value);
          out.push_back(static_cast<T>(value));
        };
        switch (format[0]) {
          case 'd': read(double()); break;
          case 'f': read(float()); break;
          case 'b': read(std::int8_t()); break;
          case 'B': read(std::uint8_t()); break;
          case 'h': read(std::int16_t()); break;
          case 'H': read(std::uint16_t()); break;
          case 'i': read(std::int32_t()); break;
          case 'I': read(std::uint32_t()); break;
          case 'l': case 'q': case 'n': read(std::int64_t()); break;
          case 'L': case 'Q': case 'N': read(std::uint64_t()); break;
          default: throw Error(std::string(what) + ": unsupported array element type '" + format + "'");
        }
      }
    return out;
  }
  if (!py::isinstance<py::sequence>(obj)) throw Error(std::string(what) + ": give an array or a sequence of numbers");
  for (py::handle item : py::reinterpret_borrow<py::sequence>(obj)) {
    if (py::isinstance<py::sequence>(item) && !py::isinstance<py::str>(item)) {
      for (py::handle x : py::reinterpret_borrow<py::sequence>(item)) out.push_back(x.cast<T>());
    } else {
      out.push_back(item.cast<T>());
    }
  }
  return out;
}

py::list vec3_list(const Vec3& v) {
  py::list l;
  l.append(v.x());
  l.append(v.y());
  l.append(v.z());
  return l;
}

py::dict run_extract(py::object vertices, py::object triangles, py::object relief_vertices, double step_height,
                     double pixel_size, const std::string& flatten, double ring_width, double smoothing) {
  const std::vector<double> V = flat_numbers<double>(vertices, "vertices");
  const std::vector<std::int64_t> F = flat_numbers<std::int64_t>(triangles, "triangles");
  const std::vector<std::int64_t> relief = flat_numbers<std::int64_t>(relief_vertices, "relief_vertices");
  if (V.size() % 3 != 0) throw Error("vertices: need 3 coordinates per vertex");
  if (F.size() % 3 != 0) throw Error("triangles: need 3 indices per triangle");
  ExtractOptions options;
  options.height_map.pixel_size = pixel_size;
  options.height_map.flattening = parse_flattening(flatten);
  options.background.ring_width = ring_width;
  options.background.smoothing = smoothing;
  if (!(step_height > 0)) throw Error("step_height must be > 0");
  if (!(ring_width > 0) || !(smoothing >= 0)) throw Error("ring_width must be > 0 and smoothing >= 0 (in units of h)");

  std::unique_ptr<Mesh> mesh;
  ExtractResult x;
  std::vector<std::string> notes;
  {
    py::gil_scoped_release release;
    mesh = std::make_unique<Mesh>(Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3));
    const std::vector<char> region = region_from_input_indices(*mesh, relief, static_cast<std::int64_t>(V.size() / 3), &notes);
    x = extract(*mesh, region, step_height, options);
  }
  x.notes.insert(x.notes.begin(), notes.begin(), notes.end());

  // Per input vertex (the caller's order): base positions and heights.
  const std::size_t n_input = V.size() / 3;
  py::list base, heights;
  for (std::size_t i = 0; i < n_input; ++i) {
    const int v = mesh->input_to_mesh(i);
    const bool moved = v >= 0 && x.background.region[v];
    const Vec3 moved_to = moved ? mesh->to_file(x.background.base_positions[v]) : Vec3::Zero();
    for (int k = 0; k < 3; ++k) base.append(moved ? moved_to[k] : V[3 * i + k]);
    heights.append(v >= 0 ? x.background.height[v] : 0.0);
  }
  py::list relief_inputs, relief_triangles, relief_heights, relief_uv;
  for (std::size_t i = 0; i < x.relief_mesh_vertices.size(); ++i) {
    relief_inputs.append(mesh->mesh_to_input(x.relief_mesh_vertices[i]));
    relief_heights.append(x.relief_heights[i]);
    relief_uv.append(x.relief_uv[i].x());
    relief_uv.append(x.relief_uv[i].y());
  }
  for (const int t : x.relief_triangles) relief_triangles.append(t);
  py::dict relief_out;
  relief_out["vertices"] = relief_inputs;
  relief_out["triangles"] = relief_triangles;
  relief_out["heights"] = relief_heights;
  relief_out["uv"] = relief_uv;

  const HeightMap& map = x.height_map;
  py::dict frame;
  frame["flattening"] = to_string(map.frame.method);
  frame["origin"] = vec3_list(map.frame.origin);
  frame["axis_u"] = vec3_list(map.frame.axis_u);
  frame["axis_v"] = vec3_list(map.frame.axis_v);
  frame["normal"] = vec3_list(map.frame.normal);
  const Distortion& d = map.frame.distortion;
  py::dict distortion;
  distortion["angle_mean"] = d.angle_mean;
  distortion["angle_max"] = d.angle_max;
  distortion["area_mean"] = d.area_mean;
  distortion["area_max"] = d.area_max;
  distortion["flipped_faces"] = d.flipped_faces;
  frame["distortion"] = distortion;
  frame["note"] = map.frame.note;
  py::dict height_map;
  height_map["width"] = map.width;
  height_map["height"] = map.height;
  height_map["pixel_size"] = map.pixel_size;
  height_map["u_left"] = map.u_left;
  height_map["v_top"] = map.v_top;
  height_map["values"] = py::bytes(reinterpret_cast<const char*>(map.values.data()), map.values.size() * sizeof(float));
  height_map["mask"] = py::bytes(reinterpret_cast<const char*>(map.mask.data()), map.mask.size());
  height_map["min_height"] = map.min_height;
  height_map["max_height"] = map.max_height;
  height_map["frame"] = frame;

  py::dict out;
  out["base_positions"] = base;
  out["heights"] = heights;
  out["relief"] = relief_out;
  out["height_map"] = height_map;
  out["model"] = x.background.model == BackgroundModel::HeightField ? "height_field" : "surface";
  out["region_vertices"] = x.background.region_vertices.size();
  out["ring_vertices"] = x.background.ring_vertices.size();
  out["ring_rms_residual"] = x.background.ring_rms_residual;
  out["ring_max_residual"] = x.background.ring_max_residual;
  out["seconds"] = x.background_seconds + x.height_map_seconds;
  out["summary"] = x.summary();
  out["notes"] = x.notes;
  return out;
}

}  // namespace

void register_extract_bindings(py::module_& m) {
  m.def("extract", &run_extract, py::arg("vertices"), py::arg("triangles"), py::arg("relief_vertices"),
        py::arg("step_height"), py::kw_only(), py::arg("pixel_size") = 0.0, py::arg("flatten") = "auto",
        py::arg("ring_width") = 3.0, py::arg("smoothing") = 0.5,
        "extract(vertices, triangles, relief_vertices, step_height, *, pixel_size=0, flatten='auto',\n"
        "        ring_width=3, smoothing=0.5) -> dict\n\n"
        "The relief's base surface, heights, relief mesh and height map (native extract.hpp).\n"
        "relief_vertices: the segmentation's input vertex indices; step_height: h (sets the background ring,\n"
        "ring_width h wide, and the smoothing length, in h). pixel_size <= 0: half the average edge.\n"
        "flatten: 'auto', 'plane' or 'conformal'. Returns a dict: base_positions (flat 3n, the input\n"
        "vertices in order, relief vertices moved onto the base), heights (n: above the base), relief\n"
        "(vertices: input indices, triangles: flat indices into them, heights, uv: flat 2 per vertex),\n"
        "height_map (width, height, pixel_size, u_left, v_top, values: float32 bytes row-major from the top,\n"
        "mask: one byte per pixel, min_height, max_height, frame), model, ring_rms_residual,\n"
        "ring_max_residual, seconds, summary, notes. Raises Error (ValueError) on an empty region, one\n"
        "with no background around it, or indices that do not fit the mesh.");
}

}  // namespace relief_snake
