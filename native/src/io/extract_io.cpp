#include "relief_snake/extract_io.hpp"

#include <png.h>

#include <atomic>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <unistd.h>

#include "relief_snake/error.hpp"

namespace relief_snake {

// --- staged files ------------------------------------------------------------

StagedFiles::~StagedFiles() {
  if (committed_) return;
  for (const auto& [temporary, final_path] : files_) std::remove(temporary.c_str());
}

std::string StagedFiles::stage(const std::string& final_path) {
  static std::atomic<unsigned> counter{0};
  // The temporary keeps the final name's extension: some writers choose the format by it.
  const std::size_t slash = final_path.find_last_of('/');
  const std::size_t dot = final_path.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  const std::string stem = has_ext ? final_path.substr(0, dot) : final_path;
  const std::string ext = has_ext ? final_path.substr(dot) : "";
  const std::string temporary = stem + ".partial-" + std::to_string(::getpid()) + "-" +
                                std::to_string(counter.fetch_add(1)) + ext;
  files_.emplace_back(temporary, final_path);
  return temporary;
}

void StagedFiles::commit() {
  for (const auto& [temporary, final_path] : files_)
    if (std::rename(temporary.c_str(), final_path.c_str()) != 0)
      throw Error("cannot move '" + temporary + "' to '" + final_path + "': " + std::strerror(errno) +
                  "; check the directory is writable");
  committed_ = true;
}

// --- EXR ---------------------------------------------------------------------

void write_height_exr(const HeightMap& map, const std::string& path) {
  const std::size_t n = static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height);
  std::vector<float> alpha(n);
  for (std::size_t k = 0; k < n; ++k) alpha[k] = map.mask[k] ? 1.0f : 0.0f;
  try {
    Imf::Header header(map.width, map.height);
    for (const char* name : {"R", "G", "B", "A"}) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::OutputFile file(path.c_str(), header);
    Imf::FrameBuffer frame;
    const std::size_t xs = sizeof(float), ys = sizeof(float) * static_cast<std::size_t>(map.width);
    char* values = reinterpret_cast<char*>(const_cast<float*>(map.values.data()));
    for (const char* name : {"R", "G", "B"}) frame.insert(name, Imf::Slice(Imf::FLOAT, values, xs, ys));
    frame.insert("A", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(alpha.data()), xs, ys));
    file.setFrameBuffer(frame);
    file.writePixels(map.height);
  } catch (const std::exception& e) {
    throw Error("cannot write the EXR '" + path + "': " + e.what());
  }
}

HeightImage read_height_exr(const std::string& path) {
  HeightImage image;
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    image.width = window.max.x - window.min.x + 1;
    image.height = window.max.y - window.min.y + 1;
    const std::size_t n = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
    image.values.assign(n, 0.0f);
    image.alpha.assign(n, 1.0f);
    const std::size_t xs = sizeof(float), ys = sizeof(float) * static_cast<std::size_t>(image.width);
    const std::ptrdiff_t shift = static_cast<std::ptrdiff_t>(window.min.x) + static_cast<std::ptrdiff_t>(window.min.y) * image.width;
    Imf::FrameBuffer frame;
    frame.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.values.data() - shift), xs, ys));
    frame.insert("A", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(image.alpha.data() - shift), xs, ys, 1, 1, 1.0));
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
  } catch (const std::exception& e) {
    throw Error("cannot read the EXR '" + path + "': " + e.what());
  }
  return image;
}

// --- PNG ---------------------------------------------------------------------

namespace {

struct PngFile {
  std::FILE* file = nullptr;
  ~PngFile() {
    if (file) std::fclose(file);
  }
};

}  // namespace

void write_height_png(const HeightMap& map, const std::string& path, double* scale_out, double* offset_out) {
  const double range = map.max_height - map.min_height;
  const double scale = range > 0 ? range / 65535.0 : 1.0 / 65535.0;
  const double offset = map.min_height;
  const std::size_t w = static_cast<std::size_t>(map.width);
  std::vector<std::vector<png_byte>> rows(static_cast<std::size_t>(map.height), std::vector<png_byte>(4 * w));
  for (std::size_t j = 0; j < rows.size(); ++j)
    for (std::size_t i = 0; i < w; ++i) {
      const std::size_t k = j * w + i;
      unsigned grey = 0, alpha = 0;
      if (map.mask[k]) {
        const double q = std::round((map.values[k] - offset) / scale);
        grey = static_cast<unsigned>(std::min(65535.0, std::max(0.0, q)));
        alpha = 65535;
      }
      png_byte* p = rows[j].data() + 4 * i;  // PNG samples are big-endian
      p[0] = static_cast<png_byte>(grey >> 8);
      p[1] = static_cast<png_byte>(grey & 0xff);
      p[2] = static_cast<png_byte>(alpha >> 8);
      p[3] = static_cast<png_byte>(alpha & 0xff);
    }
  PngFile out;
  out.file = std::fopen(path.c_str(), "wb");
  if (!out.file) throw Error("cannot write '" + path + "': " + std::strerror(errno));
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw Error("cannot write the PNG '" + path + "': out of memory");
  }
  std::vector<png_bytep> pointers(rows.size());
  for (std::size_t j = 0; j < rows.size(); ++j) pointers[j] = rows[j].data();
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error("cannot write the PNG '" + path + "' (libpng failed); check the free disk space");
  }
  png_init_io(png, out.file);
  png_set_IHDR(png, info, static_cast<png_uint_32>(map.width), static_cast<png_uint_32>(map.height), 16,
               PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, pointers.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(out.file) != 0) throw Error("writing '" + path + "' failed; check the free disk space");
  if (scale_out) *scale_out = scale;
  if (offset_out) *offset_out = offset;
}

HeightImage read_height_png(const std::string& path) {
  PngFile in;
  in.file = std::fopen(path.c_str(), "rb");
  if (!in.file) throw Error("cannot open '" + path + "': " + std::strerror(errno));
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error("cannot read the PNG '" + path + "': out of memory");
  }
  HeightImage image;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error("cannot read '" + path + "' as a PNG");
  }
  png_init_io(png, in.file);
  png_read_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  const int depth = png_get_bit_depth(png, info), type = png_get_color_type(png, info);
  if (depth != 16 || type != PNG_COLOR_TYPE_GRAY_ALPHA) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error("'" + path + "' is not a 16-bit grey + alpha PNG");
  }
  image.width = static_cast<int>(png_get_image_width(png, info));
  image.height = static_cast<int>(png_get_image_height(png, info));
  png_bytepp rows = png_get_rows(png, info);
  const std::size_t w = static_cast<std::size_t>(image.width);
  image.values.resize(w * static_cast<std::size_t>(image.height));
  image.alpha.resize(image.values.size());
  for (std::size_t j = 0; j < static_cast<std::size_t>(image.height); ++j)
    for (std::size_t i = 0; i < w; ++i) {
      const png_byte* p = rows[j] + 4 * i;
      image.values[j * w + i] = static_cast<float>((p[0] << 8) | p[1]);
      image.alpha[j * w + i] = static_cast<float>((p[2] << 8) | p[3]) / 65535.0f;
    }
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

// --- PLY ---------------------------------------------------------------------

void write_ply(const PlyMesh& mesh, const std::string& path) {
  const std::size_t nv = mesh.positions.size(), nt = mesh.triangles.size() / 3;
  for (const auto& [name, values] : mesh.vertex_properties)
    if (values.size() != nv) throw Error("PLY property '" + name + "' has the wrong length");
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error("cannot write '" + path + "'; check the directory exists and is writable");
  out << "ply\nformat binary_little_endian 1.0\ncomment written by relief-snake\n"
      << "element vertex " << nv << "\nproperty double x\nproperty double y\nproperty double z\n";
  for (const auto& property : mesh.vertex_properties) out << "property float " << property.first << "\n";
  out << "element face " << nt << "\nproperty list uchar int vertex_indices\nend_header\n";
  static_assert(sizeof(double) == 8 && sizeof(float) == 4 && sizeof(int) == 4, "PLY sizes");
  const std::size_t record = 24 + 4 * mesh.vertex_properties.size();
  std::vector<char> buffer(record * nv);  // little-endian host (x86, ARM)
  for (std::size_t v = 0; v < nv; ++v) {
    char* p = buffer.data() + record * v;
    std::memcpy(p, mesh.positions[v].data(), 24);
    for (std::size_t k = 0; k < mesh.vertex_properties.size(); ++k)
      std::memcpy(p + 24 + 4 * k, &mesh.vertex_properties[k].second[v], 4);
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  buffer.assign(13 * nt, 0);
  for (std::size_t t = 0; t < nt; ++t) {
    char* p = buffer.data() + 13 * t;
    p[0] = 3;
    std::memcpy(p + 1, &mesh.triangles[3 * t], 12);
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  out.close();
  if (!out) throw Error("writing '" + path + "' failed; check the free disk space");
}

}  // namespace relief_snake
