// relief_snake_core: the engine for Python, without numpy.
//
// Arrays come in through the buffer protocol (array.array, memoryview, numpy,
// Blender's foreach_get buffers) or as plain sequences; they are copied into
// the engine's double / int64 layout while the GIL is held, then the GIL is
// released for mesh construction and segmentation. The progress callback
// re-acquires it. No global state: every call owns its mesh (or the Mesh object
// does), so independent meshes can be segmented from several threads.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <algorithm>
#include <exception>
#include <stdexcept>
#include <type_traits>
#include <variant>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "relief_snake/detect.hpp"
#include "relief_snake/error.hpp"
#include "relief_snake/mesh.hpp"
#include "relief_snake/input_checks.hpp"
#include "relief_snake/multi_json.hpp"
#include "relief_snake/multi_segment.hpp"
#include "relief_snake/option_table.hpp"
#include "relief_snake/result_json.hpp"
#include "relief_snake/segment.hpp"

#ifndef RELIEF_SNAKE_VERSION
#define RELIEF_SNAKE_VERSION "0.0.0"
#endif

namespace py = pybind11;

namespace relief_snake {
namespace {

/// How often the progress callback receives the contour (seconds); None in between.
constexpr double kContourSeconds = 0.1;

/// Thrown (C++ side) when the progress callback cancels; becomes relief_snake_core.Cancelled.
struct CancelledError : std::exception {
  const char* what() const noexcept override { return "segmentation cancelled by the progress callback"; }
};

// --- reading arrays ----------------------------------------------------------
// Every Python object read here is held by a strong reference (py::object) for as long
// as it is used: an item's __float__ / __index__ may run arbitrary code (even mutate the
// container), so no borrowed item may outlive the call that produced it.

enum class Kind { Float, Int };

/// A wrong type in an input array: relief_snake_core.InputTypeError, which is both
/// relief_snake_core.Error (a ValueError, as before) and a TypeError.
struct InputTypeError : std::exception {
  explicit InputTypeError(std::string message) : message_(std::move(message)) {}
  const char* what() const noexcept override { return message_.c_str(); }
  std::string message_;
};

/// repr() of a value for a message, at most 40 characters (repr may itself raise: then "?").
std::string shown(py::handle value) {
  std::string text = "?";
  try {
    text = std::string(py::str(py::repr(value)));
  } catch (py::error_already_set&) {
  }
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(py::str(py::type::of(value).attr("__name__"))) + " " + text;
}

/// "vertices[12][1]" or "picks[3]": where a value is.
std::string position(const char* what, std::size_t i, long j = -1) {
  std::string s = std::string(what) + "[" + std::to_string(i) + "]";
  if (j >= 0) s += "[" + std::to_string(j) + "]";
  return s;
}

/// Element type of a buffer format string, or false if it is not a plain number type.
/// Byte-order prefixes other than native are refused: the engine reads native doubles.
bool parse_format(std::string format, char* code, bool* native_order) {
  *native_order = true;
  if (!format.empty() && std::strchr("@=<>!", format[0])) {
    const char prefix = format[0];
    format.erase(0, 1);
    // '<' is native on little-endian x86/ARM; '>' and '!' are big-endian.
    if (prefix == '>' || prefix == '!') *native_order = false;
  }
  if (format.size() != 1) return false;
  *code = format[0];
  return true;
}

bool is_float_code(char c) { return c == 'd' || c == 'f'; }
bool is_int_code(char c) { return std::strchr("bBhHiIlLqQnN", c) != nullptr; }
bool is_unsigned_code(char c) { return std::strchr("BHILQN", c) != nullptr; }

/// Reads element k (in logical C order) of a 1D or 2D buffer of any strides (negative too).
template <class T>
T element_at(const py::buffer_info& info, py::ssize_t k) {
  const char* p = static_cast<const char*>(info.ptr);
  if (info.ndim == 1) {
    p += k * info.strides[0];
  } else {
    const py::ssize_t cols = info.shape[1];
    p += (k / cols) * info.strides[0] + (k % cols) * info.strides[1];
  }
  T value;
  std::memcpy(&value, p, sizeof(T));  // memcpy: the buffer need not be aligned
  return value;
}

template <class Out>
bool read_element(const py::buffer_info& info, char code, py::ssize_t k, Out* out) {
  // Size comes from info.itemsize, not the code: 'l' is 8 bytes here but 4 on Windows.
  const bool uns = is_unsigned_code(code);
  if (is_float_code(code)) {
    if (info.itemsize == 8) *out = static_cast<Out>(element_at<double>(info, k));
    else if (info.itemsize == 4) *out = static_cast<Out>(element_at<float>(info, k));
    else return false;
    return true;
  }
  switch (info.itemsize) {
    case 1: *out = uns ? static_cast<Out>(element_at<std::uint8_t>(info, k)) : static_cast<Out>(element_at<std::int8_t>(info, k)); return true;
    case 2: *out = uns ? static_cast<Out>(element_at<std::uint16_t>(info, k)) : static_cast<Out>(element_at<std::int16_t>(info, k)); return true;
    case 4: *out = uns ? static_cast<Out>(element_at<std::uint32_t>(info, k)) : static_cast<Out>(element_at<std::int32_t>(info, k)); return true;
    case 8:
      if (uns) {
        const std::uint64_t u = element_at<std::uint64_t>(info, k);
        if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) return false;
        *out = static_cast<Out>(u);
      } else {
        *out = static_cast<Out>(element_at<std::int64_t>(info, k));
      }
      return true;
    default: return false;
  }
}

std::string type_words(Kind kind) {
  return kind == Kind::Float ? "float32 or float64 ('f' or 'd')" : "integers (int32/int64/uint32: 'i', 'l', 'q', 'I', 'L')";
}

/// Copies a buffer of rows of 3 into a flat vector (one copy; a plain memcpy when the buffer is
/// contiguous and already the engine's type). `what` names the argument in messages.
template <class Out>
std::vector<Out> read_buffer(py::handle obj, Kind kind, const char* what, bool rows_of_three) {
  py::buffer_info info;
  try {
    info = py::reinterpret_borrow<py::buffer>(obj).request();  // strided request: views are read through their strides
  } catch (py::error_already_set&) {
    throw InputTypeError(std::string(what) + ": cannot read this buffer; pass array.array, a numpy array or a list");
  }
  char code = 0;
  bool native = true;
  if (!parse_format(info.format, &code, &native) || !(kind == Kind::Float ? is_float_code(code) : is_int_code(code)))
    throw InputTypeError(std::string(what) + " must be " + type_words(kind) + ", got a " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))) + " of buffer format '" + info.format +
                         "'; convert it (e.g. array.array('" + (kind == Kind::Float ? "d" : "q") + "', ...))");
  if (!native) throw Error(std::string(what) + " is big-endian; convert it to native byte order first");
  if (!rows_of_three && info.ndim != 1)
    throw Error(std::string(what) + " must be 1D, got " + std::to_string(info.ndim) + " dimensions");
  if (info.ndim == 2) {
    if (rows_of_three && info.shape[1] != 3)
      throw Error(std::string(what) + " must have 3 columns, got shape (" + std::to_string(info.shape[0]) + ", " +
                  std::to_string(info.shape[1]) + ")");
  } else if (info.ndim != 1) {
    throw Error(std::string(what) + " must be 1D (flat) or 2D (n by 3), got " + std::to_string(info.ndim) +
                " dimensions");
  }
  const py::ssize_t count = info.ndim == 1 ? info.shape[0] : info.shape[0] * info.shape[1];
  if (rows_of_three && count % 3 != 0)
    throw Error(std::string(what) + " has " + std::to_string(count) +
                " values, not a multiple of 3; pass x, y, z (or 3 corners) per row");
  std::vector<Out> out(static_cast<std::size_t>(count));
  const bool same_type = info.itemsize == static_cast<py::ssize_t>(sizeof(Out)) &&
                         (std::is_floating_point<Out>::value ? code == 'd' : std::strchr("lqn", code) != nullptr);
  bool contiguous = info.strides.back() == info.itemsize;
  if (info.ndim == 2) contiguous = contiguous && info.strides[0] == info.shape[1] * info.itemsize;
  if (same_type && contiguous) {
    if (count > 0) std::memcpy(out.data(), info.ptr, static_cast<std::size_t>(count) * sizeof(Out));
    return out;
  }
  for (py::ssize_t k = 0; k < count; ++k)
    if (!read_element(info, code, k, &out[static_cast<std::size_t>(k)]))
      throw Error(std::string(what) + ": value " + std::to_string(k) + " does not fit in 64 bits (item size " +
                  std::to_string(info.itemsize) + ")");
  return out;
}

/// One number: an integer (anything with __index__, not bool, not float) or a float (anything
/// with __float__ or __index__). `where` names its position.
template <class Out>
Out read_number(const py::object& item, Kind kind, const char* what, const std::string& where) {
  PyObject* o = item.ptr();
  if (kind == Kind::Int) {
    // Refuse floats and strings: an index must be an integer, not something that rounds to one.
    if (!PyIndex_Check(o) || PyBool_Check(o))
      throw InputTypeError(std::string(what) + " must contain integers: " + where + " is " + shown(item));
    const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(o));
    if (!index) {
      PyErr_Clear();
      throw InputTypeError(std::string(what) + " must contain integers: " + where + " is " + shown(item) +
                           " (its __index__ failed)");
    }
    const long long v = PyLong_AsLongLong(index.ptr());
    if (v == -1 && PyErr_Occurred()) {
      PyErr_Clear();
      throw Error(std::string(what) + ": " + where + " = " + shown(index) + " is too large for 64 bits");
    }
    return static_cast<Out>(v);
  }
  const bool numeric = !PyBool_Check(o) && (PyFloat_Check(o) || PyIndex_Check(o) ||
                                            (Py_TYPE(o)->tp_as_number && Py_TYPE(o)->tp_as_number->nb_float));
  if (!numeric) throw InputTypeError(std::string(what) + " must contain numbers: " + where + " is " + shown(item));
  const double v = PyFloat_AsDouble(o);
  if (v == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    throw InputTypeError(std::string(what) + " must contain numbers: " + where + " is " + shown(item) +
                         " (its conversion to float failed)");
  }
  return static_cast<Out>(v);
}

bool is_sequence(py::handle obj) {
  return PySequence_Check(obj.ptr()) && !PyUnicode_Check(obj.ptr()) && !PyBytes_Check(obj.ptr()) &&
         !PyByteArray_Check(obj.ptr());
}

/// len(seq) as a size, or a TypeError naming `where`.
std::size_t sequence_length(py::handle seq, const std::string& where) {
  const Py_ssize_t n = PySequence_Size(seq.ptr());
  if (n < 0) {
    PyErr_Clear();
    throw InputTypeError(where + " has no length; pass a list, tuple or array");
  }
  return static_cast<std::size_t>(n);
}

/// seq[i] as a strong reference (a new reference from PySequence_GetItem).
py::object sequence_item(py::handle seq, std::size_t i, const std::string& where) {
  PyObject* item = PySequence_GetItem(seq.ptr(), static_cast<Py_ssize_t>(i));
  if (!item) {
    PyErr_Clear();
    throw InputTypeError(where + " cannot be read (its __getitem__ failed)");
  }
  return py::reinterpret_steal<py::object>(item);
}

/// Any supported array-like to a flat vector: buffer, sequence of 3-sequences or flat sequence of numbers.
template <class Out>
std::vector<Out> read_array(py::handle obj, Kind kind, const char* what, bool rows_of_three) {
  if (obj.is_none()) throw InputTypeError(std::string(what) + " is None; pass an array or a list of rows");
  if (PyObject_CheckBuffer(obj.ptr())) return read_buffer<Out>(obj, kind, what, rows_of_three);
  if (!is_sequence(obj))
    throw InputTypeError(std::string(what) + " must be a buffer (array.array, numpy) or a sequence, got " + shown(obj));
  const py::object seq = py::reinterpret_borrow<py::object>(obj);  // held for the whole read
  const std::size_t n = sequence_length(seq, what);
  std::vector<Out> out;
  out.reserve(std::min<std::size_t>(n, std::size_t(1) << 24) * (rows_of_three ? 3 : 1));
  for (std::size_t row = 0; row < n; ++row) {
    const py::object item = sequence_item(seq, row, position(what, row));
    if (is_sequence(item) || PyObject_CheckBuffer(item.ptr())) {
      if (!rows_of_three)
        throw InputTypeError(std::string(what) + " must contain single integers: " + position(what, row) + " is " +
                             shown(item));
      if (!is_sequence(item))
        throw InputTypeError(position(what, row) + " is " + shown(item) + ", not a sequence of 3 numbers");
      const std::size_t m = sequence_length(item, position(what, row));
      if (m != 3)
        throw Error(std::string(what) + ": row " + std::to_string(row) + " has " + std::to_string(m) +
                    " values, expected 3");
      for (std::size_t j = 0; j < 3; ++j) {
        const std::string where = position(what, row, static_cast<long>(j));
        out.push_back(read_number<Out>(sequence_item(item, j, where), kind, what, where));
      }
    } else {
      out.push_back(read_number<Out>(item, kind, what, position(what, row)));
    }
  }
  if (rows_of_three && out.size() % 3 != 0)
    throw Error(std::string(what) + " has " + std::to_string(out.size()) +
                " values, not a multiple of 3; pass x, y, z (or 3 corners) per row");
  return out;
}

/// allow_partial: leave non-finite coordinates to intake, which skips the faces that use them.
std::vector<double> read_vertices(py::handle obj, bool allow_partial = false) {
  std::vector<double> V = read_array<double>(obj, Kind::Float, "vertices", true);
  if (V.empty()) throw Error("vertices is empty; pass at least 3 vertices");
  if (!allow_partial)
    for (std::size_t k = 0; k < V.size(); ++k)
      if (!std::isfinite(V[k]))
        throw Error("vertex " + std::to_string(k / 3) + " has a non-finite coordinate (NaN or inf) at " +
                    position("vertices", k / 3, static_cast<long>(k % 3)) +
                    "; fix the mesh, or pass allow_partial=True to skip the faces that use it");
  return V;
}

std::vector<std::int64_t> read_triangles(py::handle obj, std::size_t n_vertices, bool allow_partial = false) {
  std::vector<std::int64_t> F = read_array<std::int64_t>(obj, Kind::Int, "triangles", true);
  if (F.empty()) throw Error("triangles is empty; pass at least one triangle");
  if (!allow_partial)
    for (std::size_t k = 0; k < F.size(); ++k)
      if (F[k] < 0 || static_cast<std::uint64_t>(F[k]) >= n_vertices)
        throw Error("triangle " + std::to_string(k / 3) + " uses vertex " + std::to_string(F[k]) +
                    ", out of range 0.." + std::to_string(static_cast<long long>(n_vertices) - 1) +
                    "; fix the triangles, or pass allow_partial=True to skip such triangles");
  return F;
}

/// Arrays to a Mesh: each array is copied once into the engine's layout (GIL held), then intake
/// reads those copies in place with the GIL released.
std::unique_ptr<Mesh> build_mesh(py::handle vertices, py::handle triangles, bool allow_partial = false) {
  const std::vector<double> V = read_vertices(vertices, allow_partial);
  const std::vector<std::int64_t> F = read_triangles(triangles, V.size() / 3, allow_partial);
  IntakeOptions intake;
  intake.allow_partial = allow_partial;
  py::gil_scoped_release release;
  return std::make_unique<Mesh>(Mesh::from_triangles(V.data(), V.size() / 3, F.data(), F.size() / 3, intake));
}

// --- segmentation ---------------------------------------------------------------

/// An advanced option's value as the engine's OptionValue, checked against its type (a Python
/// bool for booleans, an int for whole numbers, a str for choices); the option table checks the range.
OptionValue option_arg(const OptionInfo& info, py::handle value) {
  const bool is_bool = PyBool_Check(value.ptr());
  const bool is_int = !is_bool && PyLong_Check(value.ptr());
  const bool is_float = PyFloat_Check(value.ptr());
  auto wrong = [&](const char* wanted) {
    const bool ranged = info.type == OptionType::Number || info.type == OptionType::Integer;
    return Error(std::string("option ") + info.name + " must be " + wanted +
                 (ranged ? std::string(" ") + info.range : std::string()) + ", got " +
                 std::string(py::str(py::repr(value))));
  };
  switch (info.type) {
    case OptionType::Boolean:
      if (!is_bool) throw wrong("True or False");
      return value.ptr() == Py_True;
    case OptionType::Integer: {
      if (!is_int) throw wrong("an int");
      int overflow = 0;
      const long long n = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
      if (overflow) throw wrong("an int");
      return n;
    }
    case OptionType::Number:
      if (!is_int && !is_float) throw wrong("a number");
      return static_cast<double>(py::float_(py::reinterpret_borrow<py::object>(value)));
    case OptionType::Choice:
      if (!PyUnicode_Check(value.ptr())) throw wrong("a str");
      return value.cast<std::string>();
  }
  throw wrong("a value");
}

/// An advanced option's value as a Python object: float, int, bool or str by its type.
py::object option_value(const Options& options, const OptionInfo& info) {
  return std::visit(
      [](const auto& v) -> py::object {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>) return py::bool_(v);
        else if constexpr (std::is_same_v<T, long long>) return py::int_(v);
        else if constexpr (std::is_same_v<T, double>) return py::float_(v);
        else return py::str(v);
      },
      advanced_option_value(options, info.name));
}

// step_height: None (estimate it) or a number; w_int: None or "auto" (the engine chooses) or a
// number. The types are checked here, the values by the engine (input_checks.hpp).
double step_height_arg(py::handle value) {
  if (value.is_none()) return kAuto;
  if (PyBool_Check(value.ptr()) || !PyNumber_Check(value.ptr()))
    throw py::type_error("step_height must be a number > 0 or None (estimate it), got " +
                         std::string(py::str(py::repr(value))));
  return checked_step_height(py::float_(py::reinterpret_borrow<py::object>(value)), "step_height");
}

double w_int_arg(py::handle value) {
  if (value.is_none()) return kAuto;
  if (PyUnicode_Check(value.ptr())) {
    if (value.cast<std::string>() == "auto") return kAuto;
    throw Error("w_int must be a number in (0, 1] or 'auto', got " + std::string(py::str(py::repr(value))));
  }
  if (PyBool_Check(value.ptr()) || !PyNumber_Check(value.ptr()))
    throw py::type_error("w_int must be a number in (0, 1] or 'auto', got " + std::string(py::str(py::repr(value))));
  return checked_w_int(py::float_(py::reinterpret_borrow<py::object>(value)), "w_int");
}

std::vector<std::int64_t> read_picks(py::handle picks);

// Whole reliefs (issue 13): holes='auto'|'off', hole_picks=[[...], ...], min_hole_area=A (h^2),
// band_picks=[...]. Returns false for any other keyword.
bool whole_relief_option(Options* options, const std::string& name, py::handle value) {
  if (name == "holes") {
    const std::string mode = py::isinstance<py::str>(value) ? value.cast<std::string>() : std::string("?");
    if (mode != "auto" && mode != "off")
      throw Error("holes must be 'auto' or 'off', got " + std::string(py::str(py::repr(value))));
    options->holes = mode == "off" ? HoleMode::Off : HoleMode::Auto;
  } else if (name == "hole_picks") {
    options->hole_picks.clear();
    if (value.is_none()) return true;
    if (!py::isinstance<py::sequence>(value) || py::isinstance<py::str>(value))
      throw Error("hole_picks must be a list of pick lists, one per hole, e.g. [[1, 2, 3], [7, 8, 9]]");
    for (py::handle hole : value) options->hole_picks.push_back(read_picks(hole));
  } else if (name == "band_picks") {
    options->band_picks = value.is_none() ? std::vector<std::int64_t>{} : read_picks(value);
  } else if (name == "min_hole_area") {
    if (PyBool_Check(value.ptr()) || !PyNumber_Check(value.ptr()))
      throw py::type_error("min_hole_area must be a number (in h^2)");
    const double a = py::float_(py::reinterpret_borrow<py::object>(value));
    if (!std::isfinite(a) || a < 0) throw Error("min_hole_area must be a number >= 0 (in h^2)");
    options->min_hole_area = a;
  } else {
    return false;
  }
  return true;
}

Options make_options(py::handle step_height_value, py::handle w_int_value, bool open_contour,
                     const std::string& relief_side, int max_iterations, const py::kwargs& advanced) {
  const double step_height = step_height_arg(step_height_value);
  const double w_int = w_int_arg(w_int_value);
  if (relief_side != "left" && relief_side != "right" && relief_side != "auto")
    throw Error("relief_side must be \"left\", \"right\" or \"auto\", got \"" + relief_side + "\"");
  Options options;
  options.step_height = step_height;
  options.w_int = w_int;
  options.closed = !open_contour;
  options.relief_side = relief_side == "left"    ? ReliefSide::Left
                         : relief_side == "right" ? ReliefSide::Right
                                                  : ReliefSide::Auto;
  options.max_iterations = max_iterations;
  for (const auto& [key, value] : advanced) {
    const std::string name = py::str(key);
    if (whole_relief_option(&options, name, value)) continue;
    const OptionInfo* info = nullptr;
    for (const OptionInfo& o : advanced_options())
      if (name == o.name) info = &o;
    if (!info)
      throw py::type_error("segment() got an unexpected keyword argument '" + name +
                           "'; the advanced options are: " + advanced_option_names());
    set_advanced_option_value(&options, name, option_arg(*info, value));
  }
  return options;
}

std::vector<std::int64_t> read_picks(py::handle picks) {
  if (picks.is_none()) throw Error("picks is None; pass the picked vertex indices in order");
  return read_array<std::int64_t>(picks, Kind::Int, "picks", false);
}

py::tuple point(const Vec3& p) { return py::make_tuple(p.x(), p.y(), p.z()); }

// The result document (result_json.hpp) as Python objects.
py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return py::str(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list out;
      for (const auto& item : j) out.append(to_python(item));
      return std::move(out);
    }
    case nlohmann::json::value_t::object: {
      py::dict out;
      for (auto it = j.begin(); it != j.end(); ++it) out[py::str(it.key())] = to_python(it.value());
      return std::move(out);
    }
    default: return py::none();
  }
}

py::dict result_dict(const Result& r, const Options& o, const Mesh& mesh, const std::vector<std::int64_t>& picks,
                     double load_seconds, double segment_seconds) {
  ResultContext context;
  context.picks = picks;
  context.load_seconds = load_seconds;
  context.segment_seconds = segment_seconds;
  // Contour points as tuples, the form Blender's foreach_set and the add-on take.
  py::dict out = to_python(to_json(r, o, mesh, context));
  py::list contour;
  for (const Vec3& p : r.polyline) contour.append(point(p));
  out["contour"] = contour;
  py::list holes, band_contour;
  for (const std::vector<Vec3>& hole : r.hole_polylines) {
    py::list line;
    for (const Vec3& p : hole) line.append(point(p));
    holes.append(line);
  }
  for (const Vec3& p : r.band_polyline) band_contour.append(point(p));
  out["holes"] = holes;
  out["band_contour"] = band_contour;
  return out;
}

/// The Segmenters whose progress callback is running on this thread (innermost last): a
/// segment() on one of them from inside its own callback would wait forever for its own lock.
thread_local std::vector<const Segmenter*> t_running_callbacks;

/// Marks `segmenter`'s callback as running on this thread for a scope.
class CallbackScope {
 public:
  explicit CallbackScope(const Segmenter* segmenter) { t_running_callbacks.push_back(segmenter); }
  ~CallbackScope() { t_running_callbacks.pop_back(); }
  CallbackScope(const CallbackScope&) = delete;
  CallbackScope& operator=(const CallbackScope&) = delete;
};

/// Runs one segmentation with the GIL released. The Python callback (if any) is
/// called with the GIL re-acquired; its exception cancels the run and is re-raised here.
py::dict run_segmentation(Segmenter& segmenter, const Mesh& mesh, std::mutex* lock, py::handle picks_obj,
                          const Options& options, py::object progress, double seconds_before) {
  if (std::find(t_running_callbacks.begin(), t_running_callbacks.end(), &segmenter) != t_running_callbacks.end())
    throw std::runtime_error(
        "Mesh.segment was called from its own progress callback, which would wait for itself forever; "
        "segment again after the running call returns, or use another Mesh");
  const auto start = std::chrono::steady_clock::now();
  const std::vector<std::int64_t> picks = read_picks(picks_obj);
  const auto n_input = static_cast<std::int64_t>(mesh.input_vertex_count());
  for (std::int64_t p : picks)
    if (p < 0 || p >= n_input)
      throw Error("pick " + std::to_string(p) + " is not a vertex index (0.." + std::to_string(n_input - 1) + ")");
  if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    throw Error("progress must be a callable progress(phase, iteration, snaxels, contour) or None");

  std::exception_ptr callback_error;
  ProgressCallback callback;
  if (!progress.is_none()) {
    // The contour goes to Python (a list of tuples: ~1 ms for a few thousand snaxels) at
    // most every kContourSeconds and at every phase's first call; other calls get None.
    auto last_contour = std::make_shared<std::pair<std::string, std::chrono::steady_clock::time_point>>();
    const Segmenter* running = &segmenter;
    callback = [&progress, &callback_error, last_contour, running](const Progress& p) -> bool {
      py::gil_scoped_acquire acquire;
      const CallbackScope scope(running);
      if (callback_error) return false;
      try {
        const auto now = std::chrono::steady_clock::now();
        py::object contour = py::none();
        if (last_contour->first != p.phase ||
            std::chrono::duration<double>(now - last_contour->second).count() >= kContourSeconds) {
          py::list points;
          for (const Vec3& v : p.contour()) points.append(point(v));
          contour = points;
          *last_contour = {p.phase ? p.phase : "", now};
        }
        py::object answer = progress(py::str(p.phase ? p.phase : ""), p.iteration, p.snaxels, contour);
        if (answer.is_none()) return true;
        const int truth = PyObject_IsTrue(answer.ptr());
        if (truth < 0) throw py::error_already_set();
        return truth != 0;
      } catch (...) {
        // Keep the exception for the caller; the engine unwinds normally on "cancel".
        callback_error = std::current_exception();
        return false;
      }
    };
  }

  Result result;
  {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> guard(*lock);  // a Segmenter's cache is not thread-safe
    try {
      result = segmenter.segment(picks, options, callback);
    } catch (...) {
      if (!callback_error) throw;  // the callback's own exception wins over what the engine made of it
    }
  }
  if (callback_error) std::rethrow_exception(callback_error);
  if (result.status == Status::Cancelled) throw CancelledError();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result_dict(result, options, mesh, picks, seconds_before, seconds);
}

// --- several reliefs (segment_many, detect) -------------------------------------------

/// groups: a sequence of pick sequences (not a flat list of numbers).
std::vector<std::vector<std::int64_t>> read_groups(py::handle groups, std::int64_t n_input) {
  if (groups.is_none() || !is_sequence(groups))
    throw InputTypeError("groups must be a list of pick lists, e.g. [[12, 840, 77], [5, 9, 31, 2]]");
  const py::object seq = py::reinterpret_borrow<py::object>(groups);
  const std::size_t n = sequence_length(seq, "groups");
  if (n == 0) throw Error("groups is empty; pass one list of picks per relief");
  std::vector<std::vector<std::int64_t>> out;
  for (std::size_t g = 0; g < n; ++g) {
    const py::object item = sequence_item(seq, g, position("groups", g));
    if (!is_sequence(item) && !PyObject_CheckBuffer(item.ptr()))
      throw InputTypeError("groups[" + std::to_string(g) + "] is " + shown(item) +
                           ", not a list of picks; pass one list of vertex indices per relief");
    const std::string what = "groups[" + std::to_string(g) + "]";
    out.push_back(read_array<std::int64_t>(item, Kind::Int, what.c_str(), false));
    for (const std::int64_t p : out.back())
      if (p < 0 || p >= n_input)
        throw Error(what + ": pick " + std::to_string(p) + " is not a vertex index (0.." + std::to_string(n_input - 1) + ")");
  }
  return out;
}

/// The engine-side callback for a Python progress(index, phase, iteration, snaxels, contour):
/// GIL re-acquired, the contour at most every kContourSeconds, an exception kept in *error.
GroupProgressCallback group_progress(py::object& progress, std::exception_ptr* error, const Segmenter* running) {
  if (progress.is_none()) return {};
  if (!PyCallable_Check(progress.ptr()))
    throw Error("progress must be a callable progress(index, phase, iteration, snaxels, contour) or None");
  auto last = std::make_shared<std::pair<std::string, std::chrono::steady_clock::time_point>>();
  return [&progress, error, last, running](std::size_t index, const Progress& p) -> bool {
    py::gil_scoped_acquire acquire;
    const CallbackScope scope(running);
    if (*error) return false;
    try {
      const auto now = std::chrono::steady_clock::now();
      py::object contour = py::none();
      const std::string key = std::to_string(index) + (p.phase ? p.phase : "");
      if (last->first != key || std::chrono::duration<double>(now - last->second).count() >= kContourSeconds) {
        py::list points;
        for (const Vec3& v : p.contour()) points.append(point(v));
        contour = points;
        *last = {key, now};
      }
      py::object answer = progress(index, py::str(p.phase ? p.phase : ""), p.iteration, p.snaxels, contour);
      if (answer.is_none()) return true;
      const int truth = PyObject_IsTrue(answer.ptr());
      if (truth < 0) throw py::error_already_set();
      return truth != 0;
    } catch (...) {
      *error = std::current_exception();
      return false;
    }
  };
}

/// Contours of a document as tuples (the form the add-on takes), in place.
void contours_as_tuples(py::dict& entry) {
  if (!entry.contains("contour")) return;
  py::list contour;
  for (py::handle p : entry["contour"]) contour.append(py::tuple(py::reinterpret_borrow<py::list>(p)));
  entry["contour"] = contour;
}

void check_not_running(const Segmenter& segmenter, const char* method) {
  if (std::find(t_running_callbacks.begin(), t_running_callbacks.end(), &segmenter) != t_running_callbacks.end())
    throw std::runtime_error(std::string("Mesh.") + method +
                             " was called from its own progress callback, which would wait for itself forever; "
                             "call it again after the running call returns, or use another Mesh");
}

/// The Python Mesh: a validated mesh and its Segmenter (planarity cache), kept together.
class PyMesh {
 public:
  PyMesh(py::handle vertices, py::handle triangles, bool allow_partial)
      : mesh_(build_mesh(vertices, triangles, allow_partial)) {
    py::gil_scoped_release release;
    segmenter_ = std::make_unique<Segmenter>(*mesh_);
  }

  py::dict segment(py::object picks, py::object step_height, py::object w_int, bool open_contour,
                   const std::string& relief_side, int max_iterations, py::object progress, const py::kwargs& advanced) {
    const Options options = make_options(step_height, w_int, open_contour, relief_side, max_iterations, advanced);
    return run_segmentation(*segmenter_, *mesh_, &lock_, picks, options, std::move(progress), 0.0);
  }

  py::dict segment_many(py::object groups, py::object step_height, py::object w_int, bool open_contour,
                        const std::string& relief_side, int max_iterations, double max_overlap_share,
                        py::object progress, const py::kwargs& advanced) {
    check_not_running(*segmenter_, "segment_many");
    const Options options = make_options(step_height, w_int, open_contour, relief_side, max_iterations, advanced);
    if (!(max_overlap_share >= 0 && max_overlap_share <= 1))
      throw Error("max_overlap_share must be in [0, 1] (the share of a region another may share), got " +
                  std::to_string(max_overlap_share));
    MultiSegmentOptions multi;
    multi.max_overlap_share = max_overlap_share;
    const auto groups_read = read_groups(groups, static_cast<std::int64_t>(mesh_->input_vertex_count()));
    std::exception_ptr error;
    const GroupProgressCallback callback = group_progress(progress, &error, segmenter_.get());
    const auto start = std::chrono::steady_clock::now();
    MultiResult result;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> guard(lock_);
      try {
        result = relief_snake::segment_many(*segmenter_, *mesh_, groups_read, options, callback, multi);
      } catch (...) {
        if (!error) throw;
      }
    }
    if (error) std::rethrow_exception(error);
    if (result.cancelled) throw CancelledError();
    ResultContext context;
    context.segment_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    py::dict out = to_python(multi_result_json(result, groups_read, options, *mesh_, context));
    for (py::handle entry : out["reliefs"]) {
      py::dict d = py::reinterpret_borrow<py::dict>(entry);
      contours_as_tuples(d);
    }
    return out;
  }

  py::dict detect(py::object region_vertices, py::object min_area, py::object step_height, bool refine,
                  py::object background_degree, py::object w_int, int max_iterations, py::object progress,
                  const py::kwargs& advanced) {
    check_not_running(*segmenter_, "detect");
    DetectOptions options;
    options.segment = make_options(step_height, w_int, false, "auto", max_iterations, advanced);
    if (!min_area.is_none()) {
      if (PyBool_Check(min_area.ptr()) || !PyNumber_Check(min_area.ptr()))
        throw py::type_error("min_area must be a number > 0 (mesh units squared) or None, got " +
                             std::string(py::str(py::repr(min_area))));
      options.min_area = py::float_(min_area);
      if (!std::isfinite(options.min_area) || options.min_area <= 0)
        throw Error("min_area must be a finite number > 0 (mesh units squared), or None for the default");
    }
    options.refine = refine;
    if (!background_degree.is_none()) {
      if (PyBool_Check(background_degree.ptr()) || !PyLong_Check(background_degree.ptr()))
        throw py::type_error("background_degree must be an int 0..6 or None (auto), got " +
                             std::string(py::str(py::repr(background_degree))));
      options.background_degree = background_degree.cast<int>();
      if (options.background_degree < 0 || options.background_degree > 6)
        throw Error("background_degree must be between 0 and 6 (2: a quadric), or None to choose it");
    }
    std::vector<std::int64_t> region;
    if (!region_vertices.is_none()) {
      region = read_array<std::int64_t>(region_vertices, Kind::Int, "region_vertices", false);
      if (region.empty()) throw Error("region_vertices is empty; pass the region's vertex indices, or None for all");
    }
    std::exception_ptr error;
    const GroupProgressCallback callback = group_progress(progress, &error, segmenter_.get());
    DetectResult result;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> guard(lock_);
      try {
        result = relief_snake::detect(*segmenter_, *mesh_, region, options, callback);
      } catch (...) {
        if (!error) throw;
      }
    }
    if (error) std::rethrow_exception(error);
    if (result.cancelled) throw CancelledError();
    py::dict out = to_python(detect_json(result, options, *mesh_, {}));
    for (py::handle entry : out["candidates"]) {
      py::dict d = py::reinterpret_borrow<py::dict>(entry);
      contours_as_tuples(d);
    }
    return out;
  }

  double measure(std::int64_t i, std::int64_t j) const { return measure_distance(*mesh_, i, j); }
  const Mesh& mesh() const { return *mesh_; }

 private:
  std::unique_ptr<Mesh> mesh_;
  std::unique_ptr<Segmenter> segmenter_;  // holds the planarity cache between segmentations
  // Locked with the GIL released (never the other way round), so a progress callback can't deadlock.
  std::mutex lock_;
};

double measure_vertices(py::handle vertices, std::int64_t i, std::int64_t j) {
  const std::vector<double> V = read_vertices(vertices);
  const std::int64_t n = static_cast<std::int64_t>(V.size() / 3);
  for (std::int64_t k : {i, j})
    if (k < 0 || k >= n)
      throw Error("vertex index " + std::to_string(k) + " is out of range 0.." + std::to_string(n - 1));
  const double dx = V[3 * i] - V[3 * j], dy = V[3 * i + 1] - V[3 * j + 1], dz = V[3 * i + 2] - V[3 * j + 2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace
}  // namespace relief_snake

namespace relief_snake {
void register_extract_bindings(py::module_& m);  // extract_bindings.cpp
}

PYBIND11_MODULE(relief_snake_core, m) {
  using namespace relief_snake;
  register_extract_bindings(m);
  m.doc() =
      "Relief Snake engine: segment a relief on a triangle mesh from a few picked vertices and its step height "
      "(Segmenting Reliefs on Triangle Meshes, sections 5-7). Arrays go in through the buffer protocol; numpy "
      "is not needed.";
  m.attr("__version__") = RELIEF_SNAKE_VERSION;

  py::register_exception<Error>(m, "Error", PyExc_ValueError);
  py::register_exception<CancelledError>(m, "Cancelled", PyExc_Exception);
  m.attr("Error").attr("__doc__") = "Bad input or a segmentation that cannot succeed; the message says what to do.";
  m.attr("Cancelled").attr("__doc__") = "The progress callback returned False.";
  {
    // Both relief_snake_core.Error (as wrong input always was) and TypeError (what it is).
    // Kept for the process's lifetime (never released: it outlives the interpreter's module teardown).
    static PyObject* input_type_error = PyErr_NewExceptionWithDoc(
        "relief_snake_core.InputTypeError", "An input array holds a value of the wrong type; the message names it.",
        py::make_tuple(m.attr("Error"), py::handle(PyExc_TypeError)).ptr(), nullptr);
    if (!input_type_error) throw py::error_already_set();
    m.attr("InputTypeError") = py::handle(input_type_error);
    py::register_exception_translator([](std::exception_ptr p) {
      try {
        if (p) std::rethrow_exception(p);
      } catch (const InputTypeError& e) {
        PyErr_SetString(input_type_error, e.what());
      }
    });
  }

  const char* segment_doc =
      "segment(vertices, triangles, picks, step_height=None, *, w_int='auto', open_contour=False,\n"
      "        relief_side='auto',\n"
      "        max_iterations=3000, progress=None, **advanced) -> dict\n\n"
      "vertices: n by 3 (or flat 3n) floats; triangles: m by 3 (or flat 3m) integer vertex indices;\n"
      "picks: vertex indices around the relief, in order (>= 3 closed, >= 2 open); step_height: h > 0, or\n"
      "None to estimate it; w_int: in (0, 1] or 'auto'; relief_side (open contours): 'left', 'right' or\n"
      "'auto' (the side that rises).\n"
      "progress(phase: str, iteration: int, snaxels: int, contour: list of (x, y, z) or None) -> bool|None is\n"
      "called every iteration (contour: at each phase's first call and then at most every 0.1 s, None in\n"
      "between); returning False raises Cancelled. Returns the result document of docs/result-format.md\n"
      "(status: converged, doubtful or iteration_cap, with message and reasons; contour; relief_vertices;\n"
      "step_height; checks; phases; parameters; notes; mesh; timing), the same as the CLI writes.\n"
      "allow_partial=True skips (and reports in the result's mesh) triangles with out-of-range corners or\n"
      "non-finite vertices instead of raising.\n"
      "Whole reliefs (issue 13): holes='auto'|'off' (closed contours: find and segment inner holes),\n"
      "hole_picks=[[i, j, k, ...], ...] (one pick list per hole, on its floor; replaces the search),\n"
      "min_hole_area=4 (in h^2), band_picks=[...] (a band round the surface: picks is the ring on one side,\n"
      "band_picks the other; result 'band_contour'). The result's 'holes' lists each hole's contour.\n"
      "**advanced: the engine's advanced options by name (e.g. tau=0.2, exact_q=True); advanced_options()\n"
      "lists them with their types, ranges and defaults. An unknown name raises TypeError.";

  m.def(
      "segment",
      [](py::object vertices, py::object triangles, py::object picks, py::object step_height, py::object w_int,
         bool open_contour, const std::string& relief_side, int max_iterations, py::object progress,
         bool allow_partial, const py::kwargs& advanced) {
        // Options are checked before the (possibly long) mesh construction.
        const Options options = make_options(step_height, w_int, open_contour, relief_side, max_iterations, advanced);
        const auto start = std::chrono::steady_clock::now();
        std::unique_ptr<Mesh> mesh = build_mesh(vertices, triangles, allow_partial);
        std::unique_ptr<Segmenter> segmenter;
        {
          py::gil_scoped_release release;
          segmenter = std::make_unique<Segmenter>(*mesh);
        }
        std::mutex lock;
        const double before = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return run_segmentation(*segmenter, *mesh, &lock, picks, options, std::move(progress), before);
      },
      py::arg("vertices"), py::arg("triangles"), py::arg("picks"), py::arg("step_height") = py::none(), py::kw_only(),
      py::arg("w_int") = "auto", py::arg("open_contour") = false, py::arg("relief_side") = "auto",
      py::arg("max_iterations") = 3000, py::arg("progress") = py::none(), py::arg("allow_partial") = false,
      segment_doc);

  m.def(
      "advanced_options",
      [] {
        const Options defaults;
        py::list out;
        for (const OptionInfo& o : advanced_options()) {
          py::dict d;
          d["name"] = o.name;
          d["type"] = o.type == OptionType::Number    ? "number"
                      : o.type == OptionType::Integer ? "integer"
                      : o.type == OptionType::Boolean ? "boolean"
                                                      : "choice";
          d["range"] = o.range;
          d["help"] = o.help;
          d["default"] = option_value(defaults, o);
          out.append(d);
        }
        return out;
      },
      "advanced_options() -> list of dict(name, type, range, help, default): the keyword arguments segment()\n"
      "accepts beyond the main ones; most are fixed by the paper and exposed for experiments.");

  m.def("measure", [](py::object vertices, std::int64_t i, std::int64_t j) { return measure_vertices(vertices, i, j); },
        py::arg("vertices"), py::arg("i"), py::arg("j"),
        "measure(vertices, i, j) -> float: Euclidean distance between vertices i and j (to estimate h).");

  m.def(
      "mesh_report",
      [](py::object vertices, py::object triangles, bool allow_partial) {
        return build_mesh(vertices, triangles, allow_partial)->report().summary();
      },
      py::arg("vertices"), py::arg("triangles"), py::kw_only(), py::arg("allow_partial") = false,
      "mesh_report(vertices, triangles) -> str: one-line summary of what mesh intake kept, merged or refused.");

  py::class_<PyMesh>(m, "Mesh",
                     "A validated mesh that keeps its planarity cache between segmentations "
                     "(segmenting a second relief with the same h costs only the snake).")
      .def(py::init([](py::object vertices, py::object triangles, bool allow_partial) {
             return std::make_unique<PyMesh>(vertices, triangles, allow_partial);
           }),
           py::arg("vertices"), py::arg("triangles"), py::kw_only(), py::arg("allow_partial") = false,
           "Mesh(vertices, triangles, *, allow_partial=False): allow_partial skips (and reports) triangles with "
           "out-of-range corners or non-finite vertices instead of raising")
      .def_property_readonly("report", [](const PyMesh& self) { return self.mesh().report().summary(); })
      .def_property_readonly("n_vertices", [](const PyMesh& self) { return self.mesh().n_vertices(); })
      .def_property_readonly("n_faces", [](const PyMesh& self) { return self.mesh().n_faces(); })
      .def_property_readonly("average_edge", [](const PyMesh& self) { return self.mesh().average_edge_length(); })
      .def("segment", &PyMesh::segment, py::arg("picks"), py::arg("step_height") = py::none(), py::kw_only(),
           py::arg("w_int") = "auto", py::arg("open_contour") = false, py::arg("relief_side") = "auto",
           py::arg("max_iterations") = 3000, py::arg("progress") = py::none(),
           "segment(picks, step_height=None, *, w_int='auto', open_contour=False, relief_side='auto', "
           "max_iterations=3000, progress=None, **advanced) -> dict (see relief_snake_core.segment)")
      .def("segment_many", &PyMesh::segment_many, py::arg("groups"), py::arg("step_height") = py::none(),
           py::kw_only(), py::arg("w_int") = "auto", py::arg("open_contour") = false, py::arg("relief_side") = "auto",
           py::arg("max_iterations") = 3000, py::arg("max_overlap_share") = 0.02, py::arg("progress") = py::none(),
           "segment_many(groups, step_height=None, *, w_int='auto', open_contour=False, relief_side='auto',\n"
           "             max_iterations=3000, max_overlap_share=0.02, progress=None, **advanced) -> dict\n\n"
           "groups: one list of picks per relief, e.g. [[12, 840, 77], [5, 9, 31, 2]]; one snake each, sharing this\n"
           "Mesh's planarity cache. Returns the 'relief-snake-results/1' document (docs/result-format.md): reliefs\n"
           "(one result document per group, in order; status 'failed' with the message when a group could not\n"
           "run), overlaps (pairs of reliefs whose regions share vertices; a relief sharing more than\n"
           "max_overlap_share of its area is doubtful), counts, status. progress(index, phase, iteration,\n"
           "snaxels, contour) -> bool|None, index: the group being segmented; False raises Cancelled.")
      .def("detect", &PyMesh::detect, py::arg("region_vertices") = py::none(), py::kw_only(),
           py::arg("min_area") = py::none(), py::arg("step_height") = py::none(), py::arg("refine") = true,
           py::arg("background_degree") = py::none(), py::arg("w_int") = "auto", py::arg("max_iterations") = 3000,
           py::arg("progress") = py::none(),
           "detect(region_vertices=None, *, min_area=None, step_height=None, refine=True, background_degree=None,\n"
           "       w_int='auto', max_iterations=3000, progress=None, **advanced) -> dict\n\n"
           "Proposes the reliefs of the region (vertex indices; None: the whole mesh) without picks: a robust\n"
           "background fit, Otsu's threshold, components of at least min_area (mesh units squared; None:\n"
           "(12 average edges)^2), split where touching reliefs stand at separate heights, each refined by the\n"
           "snake from its own outline (refine=False: the components only). Returns the 'relief-snake-detect/1'\n"
           "document (docs/result-format.md): candidates (each a result document plus 'detection': area,\n"
           "height, score, outline), overlaps, background, notes. progress(index, phase, iteration, snaxels,\n"
           "contour) -> bool|None: phase 'background' before each background fit (iteration: fits done, index 0),\n"
           "'candidates' once the components are known (iteration: how many), then the snake's phases with\n"
           "index the candidate being refined; False raises Cancelled.")
      .def("measure", &PyMesh::measure, py::arg("i"), py::arg("j"),
           "measure(i, j) -> float: Euclidean distance between input vertices i and j.")
      .def("__repr__", [](const PyMesh& self) {
        return "<relief_snake_core.Mesh " + self.mesh().report().summary() + ">";
      });
}
