// Runs every file of the given directories through its fuzzed entry point (fuzz_entries.hpp):
// directories named .../segment* go to segment_small, all others to mesh_intake. A crash
// or an unexpected exception fails the run (ctest: intake_regression). Prints the count.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_entries.hpp"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::size_t files = 0;
  for (int a = 1; a < argc; ++a) {
    const fs::path dir(argv[a]);
    if (!fs::is_directory(dir)) {
      std::fprintf(stderr, "intake_regression: %s is not a directory\n", argv[a]);
      return 2;
    }
    const bool segment = dir.filename().string().rfind("segment", 0) == 0;
    std::vector<fs::path> paths;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file() && entry.path().filename().string()[0] != '.') paths.push_back(entry.path());
    std::sort(paths.begin(), paths.end());
    for (const fs::path& path : paths) {
      std::ifstream in(path, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
      try {
        if (segment) relief_snake::fuzz::segment_small(data, bytes.size());
        else relief_snake::fuzz::mesh_intake(data, bytes.size());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "intake_regression: %s: unexpected exception: %s\n", path.c_str(), e.what());
        return 1;
      }
      ++files;
    }
  }
  std::printf("intake_regression: %zu files, no crash\n", files);
  return files > 0 ? 0 : 1;
}
