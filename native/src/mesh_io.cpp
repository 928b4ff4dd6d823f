// Mesh file IO: strict OBJ, PLY, OFF and STL readers over a byte range.
//
// Rules shared by every format (docs/design.md, "Mesh intake"):
// - nothing is reserved for a count before the bytes that must hold it are known to exist;
// - every number is parsed (locale-free, std::from_chars) as a double or a 64-bit integer;
// - a line or element that does not parse, a file that ends early and a count that does not
//   match the contents are errors naming the line (text) or element (binary), unless
//   ReadOptions::allow_partial, which keeps what was read and says what was skipped;
// - index ranges and finiteness are not checked here but in intake, once, for files and
//   arrays alike (PolygonSoup carries the lines for its messages).
#include "relief_snake/mesh_io.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>

#include "relief_snake/error.hpp"

namespace relief_snake {

std::string PolygonSoup::face_name(std::size_t k) const {
  std::string s = "face " + std::to_string(k);
  if (k < face_lines.size()) s += " (line " + std::to_string(face_lines[k]) + ")";
  return s;
}

std::string PolygonSoup::vertex_name(std::size_t i) const {
  std::string s = "vertex " + std::to_string(i);
  if (i < vertex_lines.size()) s += " (line " + std::to_string(vertex_lines[i]) + ")";
  return s;
}

MeshFormat format_from_path(const std::string& path) {
  std::string ext;
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of("/\\");
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == "obj") return MeshFormat::Obj;
  if (ext == "ply") return MeshFormat::Ply;
  if (ext == "off") return MeshFormat::Off;
  if (ext == "stl") return MeshFormat::Stl;
  throw Error("cannot load '" + path + "': unsupported file type" + (ext.empty() ? "" : " '." + ext + "'") +
              "; give an OBJ, PLY, STL or OFF file");
}

namespace {

constexpr const char* kPartialAdvice = "re-export the file, or load the readable part with --allow-partial";

[[noreturn]] void fail(const std::string& what) { throw Error(what); }

std::string at_line(std::uint32_t line) { return "line " + std::to_string(line) + ": "; }

/// Shows a token in a message: quoted, at most 24 characters, non-printables as '?'.
std::string shown(std::string_view token) {
  std::string s;
  for (const char c : token.substr(0, 24)) s.push_back(std::isprint(static_cast<unsigned char>(c)) ? c : '?');
  return "'" + s + (token.size() > 24 ? "...'" : "'");
}

// --- text ------------------------------------------------------------------------

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Lines of a byte range, numbered from 1; '\r' before '\n' is treated as space.
class Lines {
 public:
  Lines(const char* begin, const char* end) : p_(begin), end_(end) {}
  /// Next line's bytes (without its '\n'); false at the end.
  bool next(std::string_view* line) {
    if (p_ >= end_) return false;
    const char* nl = static_cast<const char*>(std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_)));
    const char* e = nl ? nl : end_;
    *line = std::string_view(p_, static_cast<std::size_t>(e - p_));
    p_ = nl ? nl + 1 : end_;
    ++number_;
    return true;
  }
  std::uint32_t number() const { return number_; }
  const char* position() const { return p_; }
  std::size_t bytes_left() const { return static_cast<std::size_t>(end_ - p_); }

 private:
  const char* p_;
  const char* end_;
  std::uint32_t number_ = 0;
};

/// Whitespace-separated tokens of one line.
class Tokens {
 public:
  explicit Tokens(std::string_view line) : s_(line) {}
  bool next(std::string_view* token) {
    while (i_ < s_.size() && is_space(s_[i_])) ++i_;
    if (i_ >= s_.size()) return false;
    const std::size_t b = i_;
    while (i_ < s_.size() && !is_space(s_[i_])) ++i_;
    *token = s_.substr(b, i_ - b);
    return true;
  }
  /// Tokens left (from the current position).
  std::size_t count() const {
    Tokens copy = *this;
    std::string_view t;
    std::size_t n = 0;
    while (copy.next(&t)) ++n;
    return n;
  }

 private:
  std::string_view s_;
  std::size_t i_ = 0;
};

/// A line with only whitespace or a '#' comment.
bool blank_or_comment(std::string_view line) {
  for (const char c : line) {
    if (c == '#') return true;
    if (!is_space(c)) return false;
  }
  return true;
}

std::string_view strip_comment(std::string_view line) {
  const std::size_t hash = line.find('#');
  return hash == std::string_view::npos ? line : line.substr(0, hash);
}

/// A decimal number (NaN and inf literals included: intake refuses them with the vertex's line).
bool parse_double(std::string_view token, double* out, std::string* why) {
  const char* b = token.data();
  const char* e = b + token.size();
  if (b < e && *b == '+') ++b;
  const auto r = std::from_chars(b, e, *out);
  if (r.ec == std::errc::result_out_of_range) {
    *why = shown(token) + " is outside the range of a double";
    return false;
  }
  if (r.ec != std::errc() || r.ptr != e || b == e) {
    *why = shown(token) + " is not a number";
    return false;
  }
  return true;
}

bool parse_int(std::string_view token, std::int64_t* out, std::string* why) {
  const char* b = token.data();
  const char* e = b + token.size();
  if (b < e && *b == '+') ++b;
  const auto r = std::from_chars(b, e, *out);
  if (r.ec == std::errc::result_out_of_range) {
    *why = shown(token) + " does not fit in 64 bits";
    return false;
  }
  if (r.ec != std::errc() || r.ptr != e || b == e) {
    *why = shown(token) + " is not an integer";
    return false;
  }
  return true;
}

/// Appends a vertex; the soup's vectors only grow with the bytes actually read.
void push_vertex(PolygonSoup* soup, double x, double y, double z, std::uint32_t line) {
  soup->positions.insert(soup->positions.end(), {x, y, z});
  if (line) soup->vertex_lines.push_back(line);
}

void end_face(PolygonSoup* soup, std::uint32_t line) {
  soup->offsets.push_back(soup->corners.size());
  if (line) soup->face_lines.push_back(line);
}

/// Reserve for `count` elements of at least `min_bytes` each, but never more than `bytes` can hold.
std::size_t bounded(std::uint64_t count, std::size_t min_bytes, std::size_t bytes) {
  return static_cast<std::size_t>(std::min<std::uint64_t>(count, bytes / std::max<std::size_t>(1, min_bytes)));
}

// --- OBJ -------------------------------------------------------------------------

/// "v x y z [w | r g b]" and "f a b c ..." with "i", "i/t", "i//n", "i/t/n" corners; negative
/// indices count back from the last vertex defined. Other statements (vt, vn, g, o, s, usemtl,
/// mtllib, l, p, ...) carry nothing the engine uses and are skipped.
PolygonSoup read_obj(const char* data, std::size_t size, const ReadOptions& options) {
  PolygonSoup soup;
  soup.offsets.push_back(0);
  soup.index_base = 1;
  Lines lines(data, data + size);
  std::string_view line, token;
  std::string why;
  std::size_t skipped = 0;
  std::uint32_t first_skipped = 0;
  const auto bad_line = [&](const std::string& what) {
    if (!options.allow_partial) fail(at_line(lines.number()) + what + "; fix the line, or " + kPartialAdvice);
    if (skipped++ == 0) first_skipped = lines.number();
  };
  while (lines.next(&line)) {
    Tokens tokens(strip_comment(line));
    if (!tokens.next(&token)) continue;
    if (token == "v") {
      double xyz[3];
      int n = 0;
      bool ok = true;
      while (n < 3 && tokens.next(&token)) {
        if (!parse_double(token, &xyz[n], &why)) {
          ok = false;
          break;
        }
        ++n;
      }
      if (ok && n < 3) {
        ok = false;
        why = "a vertex needs x, y and z, found " + std::to_string(n) + " numbers";
      }
      if (!ok) {
        bad_line(why);
        // A skipped vertex still takes its number, or every later index would shift.
        xyz[0] = xyz[1] = xyz[2] = std::numeric_limits<double>::quiet_NaN();
      }
      push_vertex(&soup, xyz[0], xyz[1], xyz[2], lines.number());
    } else if (token == "f") {
      const std::size_t start = soup.corners.size();
      const auto n_defined = static_cast<std::int64_t>(soup.n_vertices());
      bool ok = true;
      while (tokens.next(&token)) {
        const std::string_view index = token.substr(0, token.find('/'));
        std::int64_t i = 0;
        if (!parse_int(index, &i, &why)) {
          why = "face corner " + shown(token) + " does not start with a vertex index";
          ok = false;
          break;
        }
        if (i == 0) {
          why = "face corner " + shown(token) + " is 0, but OBJ indices start at 1";
          ok = false;
          break;
        }
        // 1-based, or negative: relative to the vertices defined so far. Range is checked in intake.
        soup.corners.push_back(i > 0 ? i - 1 : (i >= -n_defined ? n_defined + i : -1));
      }
      if (ok && soup.corners.size() - start < 3) {
        why = "a face needs at least 3 corners, found " + std::to_string(soup.corners.size() - start);
        ok = false;
      }
      if (!ok) {
        soup.corners.resize(start);
        bad_line(why);
        continue;
      }
      end_face(&soup, lines.number());
    }
  }
  if (skipped)
    soup.notes.push_back("skipped " + std::to_string(skipped) + " malformed OBJ line" + (skipped == 1 ? "" : "s") +
                         " (the first at line " + std::to_string(first_skipped) + ")");
  return soup;
}

// --- OFF -------------------------------------------------------------------------

std::uint32_t read_u32_le(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

/// Binary OFF as OpenMesh writes it (little-endian int32 counts and indices, float32 coordinates;
/// after each face's indices an int32 colour count and that many float32 values).
PolygonSoup read_binary_off(const char* body, std::size_t size, const ReadOptions& options) {
  PolygonSoup soup;
  soup.offsets.push_back(0);
  const auto* p = reinterpret_cast<const unsigned char*>(body);
  const unsigned char* const end = p + size;
  const auto left = [&] { return static_cast<std::size_t>(end - p); };
  if (left() < 12) fail("the binary OFF header must give the vertex, face and edge counts (12 bytes), the file ends first");
  const std::int64_t nv = static_cast<std::int32_t>(read_u32_le(p)), nf = static_cast<std::int32_t>(read_u32_le(p + 4));
  p += 12;
  if (nv < 0 || nf < 0)
    fail("the binary OFF header gives negative counts (" + std::to_string(nv) + " vertices, " + std::to_string(nf) +
         " faces); the counts are wrong");
  const std::uint64_t needed = static_cast<std::uint64_t>(nv) * 12 + static_cast<std::uint64_t>(nf) * 20;
  if (needed > left() && !options.allow_partial)
    fail("the OFF header announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
         " faces, more than the file holds (" + std::to_string(left()) + " bytes after the header); " + kPartialAdvice);
  soup.positions.reserve(3 * bounded(static_cast<std::uint64_t>(nv), 12, left()));
  const auto f32 = [&] {
    float f;
    std::memcpy(&f, p, 4);
    p += 4;
    return static_cast<double>(f);
  };
  std::int64_t v = 0;
  for (; v < nv && left() >= 12; ++v) {
    const double x = f32(), y = f32(), z = f32();
    push_vertex(&soup, x, y, z, 0);
  }
  std::int64_t f = 0;
  std::string problem;
  if (v < nv) problem = "the file ends after " + std::to_string(v) + " of " + std::to_string(nv) + " vertices";
  for (; problem.empty() && f < nf; ++f) {
    if (left() < 4) {
      problem = "the file ends after " + std::to_string(f) + " of " + std::to_string(nf) + " faces";
      break;
    }
    const std::int64_t n = static_cast<std::int32_t>(read_u32_le(p));
    p += 4;
    if (n < 1 || static_cast<std::uint64_t>(n) * 4 + 4 > left()) {
      problem = "face " + std::to_string(f) + " announces " + std::to_string(n) + " corners, " +
                (n < 1 ? "fewer than 1" : "more than the file holds");
      break;
    }
    for (std::int64_t c = 0; c < n; ++c, p += 4) soup.corners.push_back(static_cast<std::int32_t>(read_u32_le(p)));
    const std::int64_t colours = static_cast<std::int32_t>(read_u32_le(p));
    p += 4;
    if (colours < 0 || colours > 4 || static_cast<std::uint64_t>(colours) * 4 > left()) {
      soup.corners.resize(soup.offsets.back());
      problem = "face " + std::to_string(f) + " announces " + std::to_string(colours) + " colour components (0 to 4 expected)";
      break;
    }
    p += 4 * colours;
    end_face(&soup, 0);
  }
  if (!problem.empty()) {
    if (!options.allow_partial) fail(problem + "; " + kPartialAdvice);
    soup.notes.push_back(problem + ": kept " + std::to_string(soup.n_faces()) + " faces");
  }
  return soup;
}

/// ASCII OFF, [ST][C][N][4][n]OFF: a header line, then "nv nf ne", then one vertex per line
/// (extra values such as colours ignored), then one face per line ("n i1 .. in", colour ignored).
PolygonSoup read_off(const char* data, std::size_t size, const ReadOptions& options) {
  Lines lines(data, data + size);
  std::string_view line, token;
  std::string why;
  // Header keyword: may share its line with the counts ("OFF 4 1 0").
  while (lines.next(&line) && blank_or_comment(line)) {
  }
  Tokens head(strip_comment(line));
  if (!head.next(&token) || token.size() < 3 || token.substr(token.size() - 3) != "OFF")
    fail("the OFF header keyword is missing (the file must start with OFF)");
  const std::string_view keyword = token;
  int dimension = keyword.find('4') != std::string_view::npos ? 4 : 3;
  if (head.next(&token) && token == "BINARY") {
    return read_binary_off(lines.position(), lines.bytes_left(), options);
  }
  head = Tokens(strip_comment(line));
  head.next(&token);  // the keyword again
  // Remaining header numbers ([dim] nv nf ne) may follow on the keyword line or the next lines.
  std::int64_t numbers[4];
  int have = 0;
  const int wanted = keyword.find('n') != std::string_view::npos ? 4 : 3;
  std::uint32_t count_line = lines.number();
  while (true) {
    while (have < wanted && head.next(&token)) {
      if (!parse_int(token, &numbers[have], &why))
        fail(at_line(lines.number()) + "the OFF header must give the vertex, face and edge counts, " + why);
      ++have;
    }
    if (have == wanted) break;
    if (!lines.next(&line)) fail("the OFF header must give the vertex, face and edge counts; the file ends first");
    head = Tokens(strip_comment(line));
    count_line = lines.number();
  }
  if (wanted == 4) {
    dimension = static_cast<int>(numbers[0]);
    if (dimension < 1 || dimension > 4)
      fail(at_line(count_line) + "nOFF dimension " + std::to_string(numbers[0]) + " is not 1 to 4");
  }
  const std::int64_t nv = numbers[wanted - 3], nf = numbers[wanted - 2], ne = numbers[wanted - 1];
  if (nv < 0 || nf < 0 || ne < 0)
    fail(at_line(count_line) + "the OFF header must give the vertex, face and edge counts (" + std::to_string(nv) + " " +
         std::to_string(nf) + " " + std::to_string(ne) + " are not counts)");
  // At least "x y z\n" per vertex and "3 a b c\n" per face... but a vertex line needs at least
  // dimension numbers and a separator each, a face at least 2 values.
  const std::size_t left = lines.bytes_left();
  const std::uint64_t needed = static_cast<std::uint64_t>(nv) * (2 * std::min(dimension, 3)) +
                               static_cast<std::uint64_t>(nf) * 4;
  if (needed > left && !options.allow_partial)
    fail("the OFF header announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
         " faces, more than the file holds (" + std::to_string(left) + " bytes); " + kPartialAdvice);

  PolygonSoup soup;
  soup.offsets.push_back(0);
  soup.positions.reserve(3 * bounded(static_cast<std::uint64_t>(nv), 6, left));
  soup.vertex_lines.reserve(bounded(static_cast<std::uint64_t>(nv), 6, left));
  std::string problem;
  std::uint32_t problem_line = 0;
  std::int64_t v = 0;
  while (v < nv) {
    if (!lines.next(&line)) {
      problem = "the file ends after " + std::to_string(v) + " of " + std::to_string(nv) + " vertices";
      break;
    }
    if (blank_or_comment(line)) continue;
    Tokens tokens(strip_comment(line));
    double xyz[4] = {0, 0, 0, 1};
    int n = 0;
    while (n < dimension && tokens.next(&token)) {
      if (!parse_double(token, &xyz[n], &why)) break;
      ++n;
    }
    if (n < dimension) {
      problem = "vertex " + std::to_string(v) + ": " +
                (why.empty() ? "needs " + std::to_string(dimension) + " coordinates" : why);
      problem_line = lines.number();
      break;
    }
    if (dimension == 4) {
      // Homogeneous coordinates: divide by w (w = 0 makes them non-finite, refused by intake).
      for (int k = 0; k < 3; ++k) xyz[k] /= xyz[3];
    }
    push_vertex(&soup, xyz[0], xyz[1], xyz[2], lines.number());
    ++v;
  }
  std::int64_t f = 0;
  while (problem.empty() && f < nf) {
    if (!lines.next(&line)) {
      problem = "the file ends after " + std::to_string(f) + " of " + std::to_string(nf) + " faces";
      break;
    }
    if (blank_or_comment(line)) continue;
    Tokens tokens(strip_comment(line));
    std::int64_t n = 0;
    tokens.next(&token);
    if (!parse_int(token, &n, &why)) {
      problem = "face " + std::to_string(f) + ": its corner count " + why +
                (v == nv && f == 0 ? " (is the vertex count in the header too small?)" : "");
      problem_line = lines.number();
      break;
    }
    // A face line holds its corners: a count beyond the line's values is a broken count.
    const std::size_t listed = tokens.count();
    if (n < 1 || static_cast<std::uint64_t>(n) > listed) {
      problem = "face " + std::to_string(f) + " announces " + std::to_string(n) + " corners, " +
                (n < 1 ? "fewer than 1" : "but its line lists " + std::to_string(listed));
      problem_line = lines.number();
      break;
    }
    std::int64_t c = 0;
    for (; c < n && tokens.next(&token); ++c) {
      std::int64_t i = 0;
      if (!parse_int(token, &i, &why)) break;
      soup.corners.push_back(i);
    }
    if (c < n) {
      soup.corners.resize(soup.offsets.back());
      problem = "face " + std::to_string(f) + ": " +
                (why.empty() ? "announces " + std::to_string(n) + " corners but lists " + std::to_string(c) : "corner " + why);
      problem_line = lines.number();
      break;
    }
    end_face(&soup, lines.number());
    ++f;
  }
  if (!problem.empty()) {
    const std::string where = problem_line ? at_line(problem_line) : "";
    if (!options.allow_partial) fail(where + problem + "; " + kPartialAdvice);
    soup.notes.push_back(where + problem + ": kept " + std::to_string(soup.n_vertices()) + " vertices and " +
                         std::to_string(soup.n_faces()) + " faces");
  }
  return soup;
}

// --- STL -------------------------------------------------------------------------

PolygonSoup read_binary_stl(const char* data, std::size_t size, const ReadOptions& options) {
  PolygonSoup soup;
  soup.offsets.push_back(0);
  if (size < 84) fail("a binary STL needs an 84-byte header, the file has " + std::to_string(size) + " bytes");
  const std::uint64_t announced = read_u32_le(reinterpret_cast<const unsigned char*>(data) + 80);
  const std::uint64_t present = (size - 84) / 50;
  std::uint64_t n = announced;
  if (announced * 50 + 84 != size) {
    const std::string problem = "the binary STL header announces " + std::to_string(announced) + " triangles (" +
                                std::to_string(announced * 50 + 84) + " bytes) but the file has " +
                                std::to_string(size) + " bytes";
    if (!options.allow_partial) fail(problem + "; " + kPartialAdvice);
    n = std::min(announced, present);
    soup.notes.push_back(problem + ": kept " + std::to_string(n) + " triangles");
  }
  soup.positions.reserve(9 * n);
  soup.corners.reserve(3 * n);
  soup.offsets.reserve(n + 1);
  const char* p = data + 84;
  for (std::uint64_t t = 0; t < n; ++t, p += 50) {
    float c[9];
    std::memcpy(c, p + 12, sizeof c);  // skip the stored normal: intake recomputes it
    for (int k = 0; k < 3; ++k) {
      soup.corners.push_back(static_cast<std::int64_t>(soup.n_vertices()));
      push_vertex(&soup, c[3 * k], c[3 * k + 1], c[3 * k + 2], 0);
    }
    end_face(&soup, 0);
  }
  return soup;
}

/// ASCII STL: "solid", then facets of "vertex x y z" lines, then "endsolid". Keywords are
/// read as tokens; a facet ends at "endfacet" and needs 3 (or more: a polygon) vertices.
PolygonSoup read_ascii_stl(const char* data, std::size_t size, const ReadOptions& options) {
  PolygonSoup soup;
  soup.offsets.push_back(0);
  Lines lines(data, data + size);
  std::string_view line, token;
  std::string why, problem;
  std::uint32_t problem_line = 0;
  bool in_facet = false, in_solid = false, ended = false;
  std::size_t facet_start = 0, facet_vertices = 0;
  std::uint32_t facet_line = 0;
  while (problem.empty() && lines.next(&line)) {
    Tokens tokens(line);
    if (!tokens.next(&token)) continue;
    if (token == "vertex") {
      double xyz[3];
      int n = 0;
      while (n < 3 && tokens.next(&token) && parse_double(token, &xyz[n], &why)) ++n;
      if (!in_facet) why = "a vertex outside a facet";
      if (n < 3 || !in_facet) {
        problem = why.empty() ? "a vertex needs x, y and z" : why;
        problem_line = lines.number();
        break;
      }
      soup.corners.push_back(static_cast<std::int64_t>(soup.n_vertices()));
      push_vertex(&soup, xyz[0], xyz[1], xyz[2], lines.number());
      ++facet_vertices;
    } else if (token == "facet") {
      if (in_facet) {
        problem = "a facet starts before the previous one ended (endfacet missing)";
        problem_line = lines.number();
      }
      in_facet = true;
      facet_start = soup.corners.size();
      facet_vertices = 0;
      facet_line = lines.number();
    } else if (token == "endfacet") {
      if (!in_facet || facet_vertices < 3) {
        problem = in_facet ? "a facet has " + std::to_string(facet_vertices) + " vertices, at least 3 are needed"
                           : "endfacet without facet";
        problem_line = lines.number();
        break;
      }
      in_facet = false;
      end_face(&soup, facet_line);
    } else if (token == "endsolid") {
      ended = true;
      in_solid = false;
      if (in_facet) {
        problem = "the solid ends inside a facet";
        problem_line = lines.number();
      }
    } else if (token == "solid") {
      in_solid = true;  // files may hold several solids, one after the other
    } else if (token != "outer" && token != "endloop") {
      problem = "unexpected " + shown(token) + " in an ASCII STL";
      problem_line = lines.number();
    }
  }
  if (problem.empty() && (!ended || in_solid)) problem = "the file ends without 'endsolid' (after " + std::to_string(soup.n_faces()) + " facets)";
  if (!problem.empty()) {
    if (in_facet) soup.corners.resize(facet_start);
    soup.positions.resize(3 * std::min(soup.n_vertices(), soup.corners.size()));
    soup.vertex_lines.resize(soup.n_vertices());
    const std::string where = problem_line ? at_line(problem_line) : "";
    if (!options.allow_partial) fail(where + problem + "; " + kPartialAdvice);
    soup.notes.push_back(where + problem + ": kept " + std::to_string(soup.n_faces()) + " facets");
  }
  return soup;
}

bool starts_with_solid(const char* data, std::size_t size) {
  std::size_t i = 0;
  while (i < size && is_space(data[i])) ++i;
  return size - i >= 5 && std::memcmp(data + i, "solid", 5) == 0;
}

PolygonSoup read_stl(const char* data, std::size_t size, const ReadOptions& options) {
  // Binary STL headers may start with "solid" too: a size that matches the binary count decides.
  if (size >= 84) {
    const std::uint64_t n = read_u32_le(reinterpret_cast<const unsigned char*>(data) + 80);
    if (n * 50 + 84 == size) return read_binary_stl(data, size, options);
  }
  if (starts_with_solid(data, size)) {
    // ASCII only if the start is text (a binary header may say "solid" and hold garbage).
    const std::size_t probe = std::min<std::size_t>(size, 512);
    bool text = true;
    for (std::size_t i = 0; i < probe && text; ++i) {
      const auto c = static_cast<unsigned char>(data[i]);
      text = c == '\n' || c == '\t' || c == '\r' || (c >= 32 && c < 127);
    }
    if (text) return read_ascii_stl(data, size, options);
  }
  return read_binary_stl(data, size, options);
}

// --- PLY -------------------------------------------------------------------------

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool ply_type(std::string_view name, PlyType* type) {
  static const std::array<std::pair<std::string_view, PlyType>, 16> names = {{
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},      {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},   {"short", PlyType::Int16},    {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16}, {"uint16", PlyType::UInt16},  {"int", PlyType::Int32},
      {"int32", PlyType::Int32},   {"uint", PlyType::UInt32},    {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64},
  }};
  for (const auto& [n, t] : names)
    if (n == name) {
      *type = t;
      return true;
    }
  return false;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::Int8: case PlyType::UInt8: return 1;
    case PlyType::Int16: case PlyType::UInt16: return 2;
    case PlyType::Int32: case PlyType::UInt32: case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 1;
}

bool ply_integer(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::uint32_t line = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { Ascii, BinaryLittle, BinaryBig };

struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  std::size_t header_bytes = 0;
  std::uint32_t header_lines = 0;
};

/// The header grammar: ply, format, then element / property / comment / obj_info lines, end_header.
PlyHeader parse_ply_header(const char* data, std::size_t size) {
  PlyHeader h;
  Lines lines(data, data + std::min<std::size_t>(size, 1 << 20));  // headers are small; 1 MB is generous
  std::string_view line, token;
  std::string why;
  if (!lines.next(&line) || Tokens(line).count() != 1 || (Tokens(line).next(&token), token != "ply"))
    fail("a PLY file must start with the line 'ply'");
  bool have_format = false, ended = false;
  while (!ended && lines.next(&line)) {
    Tokens t(line);
    if (!t.next(&token)) continue;
    const std::string where = at_line(lines.number());
    if (token == "comment" || token == "obj_info") continue;
    if (token == "format") {
      std::string_view kind, version;
      if (!t.next(&kind) || !t.next(&version)) fail(where + "the format line needs a format and a version");
      if (kind == "ascii") h.format = PlyFormat::Ascii;
      else if (kind == "binary_little_endian") h.format = PlyFormat::BinaryLittle;
      else if (kind == "binary_big_endian") h.format = PlyFormat::BinaryBig;
      else fail(where + "unknown PLY format " + shown(kind) + " (ascii, binary_little_endian or binary_big_endian)");
      if (version != "1.0") fail(where + "unsupported PLY version " + shown(version) + " (1.0 expected)");
      have_format = true;
    } else if (token == "element") {
      if (!have_format) fail(where + "an element comes before the format line");
      std::string_view name, count;
      std::int64_t n = 0;
      if (!t.next(&name) || !t.next(&count) || !parse_int(count, &n, &why) || n < 0)
        fail(where + "a PLY element has no valid count (element NAME COUNT)");
      h.elements.push_back({std::string(name), static_cast<std::uint64_t>(n), lines.number(), {}});
    } else if (token == "property") {
      if (h.elements.empty()) fail(where + "a property comes before any element line");
      PlyProperty p;
      std::string_view type, name;
      if (!t.next(&type)) fail(where + "a property needs a type and a name");
      if (type == "list") {
        std::string_view count_type, item_type;
        if (!t.next(&count_type) || !t.next(&item_type) || !t.next(&name))
          fail(where + "a list property needs a count type, an item type and a name");
        p.is_list = true;
        if (!ply_type(count_type, &p.count_type) || !ply_integer(p.count_type))
          fail(where + "list count type " + shown(count_type) + " is not an integer type");
        if (!ply_type(item_type, &p.type)) fail(where + "unknown property type " + shown(item_type));
      } else {
        if (!ply_type(type, &p.type)) fail(where + "unknown property type " + shown(type));
        if (!t.next(&name)) fail(where + "a property needs a name");
      }
      std::string_view extra;
      if (t.next(&extra)) fail(where + "unexpected " + shown(extra) + " after the property name");
      p.name = std::string(name);
      h.elements.back().properties.push_back(p);
    } else if (token == "end_header") {
      ended = true;
    } else {
      fail(where + "unknown PLY header line " + shown(token));
    }
  }
  if (!ended) fail("the PLY header has no end_header line");
  for (const PlyElement& el : h.elements)
    if (el.count > 0 && el.properties.empty())
      fail(at_line(el.line) + "element '" + el.name + "' has a count but no properties");
  if (!have_format) fail("the PLY header has no format line");
  h.header_bytes = static_cast<std::size_t>(lines.position() - data);
  h.header_lines = lines.number();
  return h;
}

template <class T>
T load_scalar(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// One binary value as a double (floats) and an int64 (integers); p must hold ply_size(t) bytes.
void load_ply_value(const unsigned char* p, PlyType t, bool swap, double* d, std::int64_t* i) {
  switch (t) {
    case PlyType::Int8: *i = load_scalar<std::int8_t>(p, swap); *d = static_cast<double>(*i); return;
    case PlyType::UInt8: *i = load_scalar<std::uint8_t>(p, swap); *d = static_cast<double>(*i); return;
    case PlyType::Int16: *i = load_scalar<std::int16_t>(p, swap); *d = static_cast<double>(*i); return;
    case PlyType::UInt16: *i = load_scalar<std::uint16_t>(p, swap); *d = static_cast<double>(*i); return;
    case PlyType::Int32: *i = load_scalar<std::int32_t>(p, swap); *d = static_cast<double>(*i); return;
    case PlyType::UInt32: *i = load_scalar<std::uint32_t>(p, swap); *d = static_cast<double>(*i); return;
    case PlyType::Float32: *d = load_scalar<float>(p, swap); *i = -1; return;
    case PlyType::Float64: *d = load_scalar<double>(p, swap); *i = -1; return;
  }
}

/// Where each property of the vertex and face elements goes.
struct PlyRoles {
  int vertex_element = -1, face_element = -1;
  int xyz[3] = {-1, -1, -1};  ///< property indices of x, y, z in the vertex element
  int indices = -1;           ///< the face element's vertex list
};

PlyRoles ply_roles(const PlyHeader& h) {
  PlyRoles r;
  for (std::size_t e = 0; e < h.elements.size(); ++e) {
    const PlyElement& el = h.elements[e];
    if (el.name == "vertex" && r.vertex_element < 0) {
      r.vertex_element = static_cast<int>(e);
      for (std::size_t k = 0; k < el.properties.size(); ++k) {
        const PlyProperty& p = el.properties[k];
        for (int c = 0; c < 3; ++c)
          if (p.name == std::string(1, static_cast<char>('x' + c))) {
            if (p.is_list) fail(at_line(el.line) + "vertex property " + p.name + " is a list, a number is expected");
            r.xyz[c] = static_cast<int>(k);
          }
      }
      for (int c = 0; c < 3; ++c)
        if (r.xyz[c] < 0)
          fail(at_line(el.line) + "the vertex element has no '" + std::string(1, static_cast<char>('x' + c)) + "' property");
    } else if (el.name == "face" && r.face_element < 0) {
      r.face_element = static_cast<int>(e);
      for (std::size_t k = 0; k < el.properties.size(); ++k) {
        const PlyProperty& p = el.properties[k];
        if (p.name == "vertex_indices" || p.name == "vertex_index") {
          if (!p.is_list || !ply_integer(p.type))
            fail(at_line(el.line) + "face property " + p.name + " must be a list of integers");
          r.indices = static_cast<int>(k);
        }
      }
      if (r.indices < 0) fail(at_line(el.line) + "the face element has no 'vertex_indices' list property");
    }
  }
  if (r.vertex_element < 0) fail("the PLY header declares no vertex element");
  return r;
}

/// The fewest bytes an element's instance takes (binary: scalars and list counts; ASCII: a value
/// and a separator per property).
std::uint64_t ply_min_bytes(const PlyElement& el, PlyFormat format) {
  std::uint64_t n = 0;
  for (const PlyProperty& p : el.properties)
    n += format == PlyFormat::Ascii ? 2 : ply_size(p.is_list ? p.count_type : p.type);
  return std::max<std::uint64_t>(n, format == PlyFormat::Ascii ? 1 : 0);
}

PolygonSoup read_ply(const char* data, std::size_t size, const ReadOptions& options) {
  const PlyHeader h = parse_ply_header(data, size);
  const PlyRoles roles = ply_roles(h);
  const std::size_t body = size - h.header_bytes;

  // Every count against the bytes after the header (overflow-safe: counts < 2^63, sizes <= 16).
  std::uint64_t needed = 0;
  for (const PlyElement& el : h.elements) {
    const std::uint64_t each = ply_min_bytes(el, h.format);
    if (each && el.count > (std::numeric_limits<std::uint64_t>::max() - needed) / each) {
      needed = std::numeric_limits<std::uint64_t>::max();
      break;
    }
    needed += el.count * each;
  }
  if (needed > body && !options.allow_partial)
    fail("the PLY header announces more elements than the file holds (" +
         (needed == std::numeric_limits<std::uint64_t>::max() ? std::string("over 2^64") : std::to_string(needed)) +
         " bytes or more needed, " + std::to_string(body) + " after the header); " + kPartialAdvice);

  PolygonSoup soup;
  soup.offsets.push_back(0);
  const PlyElement& vertex_el = h.elements[static_cast<std::size_t>(roles.vertex_element)];
  soup.positions.reserve(3 * bounded(vertex_el.count, static_cast<std::size_t>(ply_min_bytes(vertex_el, h.format)), body));
  if (roles.face_element >= 0) {
    const PlyElement& face_el = h.elements[static_cast<std::size_t>(roles.face_element)];
    const std::size_t faces = bounded(face_el.count, static_cast<std::size_t>(ply_min_bytes(face_el, h.format)), body);
    soup.offsets.reserve(faces + 1);
  }

  std::string problem;
  std::uint32_t problem_line = 0;
  const bool ascii = h.format == PlyFormat::Ascii;
  const std::uint16_t one = 1;
  unsigned char first_byte = 0;
  std::memcpy(&first_byte, &one, 1);
  const bool swap = (h.format == PlyFormat::BinaryBig) == (first_byte == 1);
  Lines lines(data + h.header_bytes, data + size);
  const auto* p = reinterpret_cast<const unsigned char*>(data + h.header_bytes);
  const unsigned char* const end = reinterpret_cast<const unsigned char*>(data + size);
  std::string_view line, token;
  std::string why;
  std::uint32_t line_base = h.header_lines;

  for (std::size_t e = 0; e < h.elements.size() && problem.empty(); ++e) {
    const PlyElement& el = h.elements[e];
    const bool is_vertex = static_cast<int>(e) == roles.vertex_element;
    const bool is_face = static_cast<int>(e) == roles.face_element;
    for (std::uint64_t k = 0; k < el.count && problem.empty(); ++k) {
      double xyz[3] = {0, 0, 0};
      const auto name = [&] { return el.name + " " + std::to_string(k); };
      if (ascii) {
        // One instance per line, exactly as many values as its properties declare: this is
        // what catches a vertex count that is too large (face lines read as vertices).
        do {
          if (!lines.next(&line)) {
            problem = "the file ends after " + std::to_string(k) + " of " + std::to_string(el.count) + " " + el.name +
                      " elements";
            break;
          }
        } while (Tokens(line).count() == 0);
        if (!problem.empty()) break;
        const std::uint32_t here = line_base + lines.number();
        Tokens t(line);
        for (std::size_t q = 0; q < el.properties.size() && problem.empty(); ++q) {
          const PlyProperty& prop = el.properties[q];
          std::uint64_t n = 1;
          if (prop.is_list) {
            std::int64_t count = 0;
            if (!t.next(&token) || !parse_int(token, &count, &why) || count < 0) {
              problem = name() + ": list '" + prop.name + "' has no valid count" + (why.empty() ? "" : " (" + why + ")");
              break;
            }
            n = static_cast<std::uint64_t>(count);
          }
          for (std::uint64_t j = 0; j < n; ++j) {
            if (!t.next(&token)) {
              problem = name() + " has fewer values than its properties declare";
              break;
            }
            double d = 0;
            std::int64_t i = 0;
            const bool ok = ply_integer(prop.type) ? parse_int(token, &i, &why) : parse_double(token, &d, &why);
            if (!ok) {
              problem = name() + ", property '" + prop.name + "': " + why;
              break;
            }
            if (ply_integer(prop.type)) d = static_cast<double>(i);
            if (is_vertex)
              for (int c = 0; c < 3; ++c)
                if (roles.xyz[c] == static_cast<int>(q)) xyz[c] = d;
            if (is_face && roles.indices == static_cast<int>(q)) soup.corners.push_back(i);
          }
        }
        if (problem.empty() && t.next(&token))
          problem = name() + " has more values than its properties declare (" + shown(token) +
                    "; does the header's " + el.name + " count match the file?)";
        if (!problem.empty()) {
          problem_line = here;
          break;
        }
        if (is_vertex) push_vertex(&soup, xyz[0], xyz[1], xyz[2], here);
        if (is_face) end_face(&soup, here);
      } else {
        for (std::size_t q = 0; q < el.properties.size() && problem.empty(); ++q) {
          const PlyProperty& prop = el.properties[q];
          std::uint64_t n = 1;
          double d = 0;
          std::int64_t i = 0;
          if (prop.is_list) {
            if (static_cast<std::size_t>(end - p) < ply_size(prop.count_type)) {
              problem = "the file ends inside " + name();
              break;
            }
            load_ply_value(p, prop.count_type, swap, &d, &i);
            p += ply_size(prop.count_type);
            // The list must fit in the bytes left: a huge or negative count is refused here.
            if (i < 0 || static_cast<std::uint64_t>(i) > static_cast<std::size_t>(end - p) / ply_size(prop.type)) {
              problem = name() + ": list '" + prop.name + "' announces " + std::to_string(i) + " items, " +
                        (i < 0 ? "a negative count" : "more than the file holds");
              break;
            }
            n = static_cast<std::uint64_t>(i);
          }
          const std::size_t item = ply_size(prop.type);
          if (static_cast<std::uint64_t>(end - p) < n * item) {
            problem = "the file ends inside " + name() + " (after " + std::to_string(k) + " of " +
                      std::to_string(el.count) + " " + el.name + " elements)";
            break;
          }
          const bool face_list = is_face && roles.indices == static_cast<int>(q);
          for (std::uint64_t j = 0; j < n; ++j, p += item) {
            if (!is_vertex && !face_list) continue;
            load_ply_value(p, prop.type, swap, &d, &i);
            if (face_list) soup.corners.push_back(i);
            else
              for (int c = 0; c < 3; ++c)
                if (roles.xyz[c] == static_cast<int>(q)) xyz[c] = d;
          }
        }
        if (!problem.empty()) break;
        if (is_vertex) push_vertex(&soup, xyz[0], xyz[1], xyz[2], 0);
        if (is_face) end_face(&soup, 0);
      }
    }
    if (!problem.empty()) {
      // Drop the half-read face; the vertices read so far stay.
      soup.corners.resize(soup.offsets.back());
    }
  }
  if (problem.empty()) {
    if (ascii) {
      while (lines.next(&line))
        if (Tokens(line).count() != 0) {
          problem = "there is data after the last element declared in the header";
          problem_line = line_base + lines.number();
          break;
        }
    } else if (p != end) {
      problem = std::to_string(end - p) + " bytes after the last element declared in the header";
    }
  }
  if (!problem.empty()) {
    const std::string where = problem_line ? at_line(problem_line) : "";
    if (!options.allow_partial) fail(where + problem + "; " + kPartialAdvice);
    soup.notes.push_back(where + problem + ": kept " + std::to_string(soup.n_vertices()) + " vertices and " +
                         std::to_string(soup.n_faces()) + " faces");
  }
  return soup;
}

/// A read-only view of a file's bytes (mmap; empty files have no mapping).
class MappedFile {
 public:
  explicit MappedFile(const std::string& path) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw Error("cannot open '" + path + "': no such file or not readable; check the path");
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd_);
      throw Error("cannot read '" + path + "': not a regular file; give a mesh file");
    }
    size_ = static_cast<std::size_t>(st.st_size);
    if (size_ > 0) {
      void* m = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd_, 0);
      if (m == MAP_FAILED) {
        ::close(fd_);
        throw Error("cannot read '" + path + "': the file cannot be mapped into memory");
      }
      data_ = static_cast<const char*>(m);
      ::madvise(m, size_, MADV_SEQUENTIAL);
    }
  }
  ~MappedFile() {
    if (data_) ::munmap(const_cast<char*>(data_), size_);
    if (fd_ >= 0) ::close(fd_);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  const char* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  int fd_ = -1;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
};

const char* format_name(MeshFormat f) {
  switch (f) {
    case MeshFormat::Obj: return "OBJ";
    case MeshFormat::Ply: return "PLY";
    case MeshFormat::Off: return "OFF";
    case MeshFormat::Stl: return "STL";
  }
  return "mesh";
}

}  // namespace

PolygonSoup read_mesh_bytes(const char* data, std::size_t size, MeshFormat format, const ReadOptions& options) {
  if (size == 0 || data == nullptr) fail(std::string("the ") + format_name(format) + " file is empty");
  switch (format) {
    case MeshFormat::Obj: return read_obj(data, size, options);
    case MeshFormat::Ply: return read_ply(data, size, options);
    case MeshFormat::Off: return read_off(data, size, options);
    case MeshFormat::Stl: return read_stl(data, size, options);
  }
  fail("unknown mesh format");
}

PolygonSoup read_mesh_file(const std::string& path, const ReadOptions& options) {
  const MeshFormat format = format_from_path(path);
  const MappedFile file(path);
  try {
    return read_mesh_bytes(file.data(), file.size(), format, options);
  } catch (const Error& e) {
    throw Error("cannot read '" + path + "' as " + format_name(format) + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw Error("cannot read '" + path + "': out of memory for " + std::to_string(file.size()) + " bytes of mesh");
  }
}

}  // namespace relief_snake
